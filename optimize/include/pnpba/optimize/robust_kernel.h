// Robust kernels with g2o's semantics: rho acts on s = e^T Omega e (the edge's chi2), and the
// normal equations are weighted by rho'(s) only (first order, as g2o does). robustify() fills
// (rho(s), rho'(s), rho''(s)), which is also exactly what a ceres::LossFunction returns, so the
// Ceres back end uses the same functions.
#pragma once

#include <Eigen/Core>

namespace pnpba {

class RobustKernel {
 public:
  explicit RobustKernel(double delta = 1.0) : delta_(delta) {}
  virtual ~RobustKernel() = default;
  virtual void robustify(double s, Eigen::Vector3d& rho) const = 0;
  void setDelta(double delta) { delta_ = delta; }
  double delta() const { return delta_; }

 protected:
  double delta_;
};

// rho(s) = s for s <= delta^2, else 2 delta sqrt(s) - delta^2.
class RobustKernelHuber : public RobustKernel {
 public:
  using RobustKernel::RobustKernel;
  void robustify(double s, Eigen::Vector3d& rho) const override;
};

// rho(s) = delta^2 log(1 + s / delta^2).
class RobustKernelCauchy : public RobustKernel {
 public:
  using RobustKernel::RobustKernel;
  void robustify(double s, Eigen::Vector3d& rho) const override;
};

}  // namespace pnpba
