#include "pnpba/optimize/robust_kernel.h"

#include <cmath>

namespace pnpba {

void RobustKernelHuber::robustify(double s, Eigen::Vector3d& rho) const {
  const double d2 = delta_ * delta_;
  if (s <= d2) {
    rho = Eigen::Vector3d(s, 1.0, 0.0);
    return;
  }
  const double sqrt_s = std::sqrt(s);
  rho[0] = 2.0 * delta_ * sqrt_s - d2;
  rho[1] = delta_ / sqrt_s;
  rho[2] = -0.5 * rho[1] / s;
}

void RobustKernelCauchy::robustify(double s, Eigen::Vector3d& rho) const {
  const double d2 = delta_ * delta_;
  const double inv_d2 = 1.0 / d2;
  const double aux = 1.0 + s * inv_d2;
  rho[0] = d2 * std::log(aux);
  rho[1] = 1.0 / aux;
  rho[2] = -inv_d2 * rho[1] * rho[1];
}

}  // namespace pnpba
