// RobustKernelHuber's rho[0] and rho[1] as plain functions, for the solvers that work without
// edge objects (pose_only.cpp, rgbd_pair.cpp): the robust cost of a chi2 and the weight its
// J' W J and J' W e carry. A width of 0 or less means no kernel.
#pragma once

#include <cmath>

namespace pnpba::internal {

inline double huberCost(double chi2, double delta) {
  if (delta <= 0) return chi2;
  const double d2 = delta * delta;
  return chi2 <= d2 ? chi2 : 2.0 * delta * std::sqrt(chi2) - d2;
}

inline double huberWeight(double chi2, double delta) {
  if (delta <= 0) return 1.0;
  return chi2 <= delta * delta ? 1.0 : delta / std::sqrt(chi2);
}

}  // namespace pnpba::internal
