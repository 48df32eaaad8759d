// g2o's Levenberg-Marquardt damping after an accepted step, shared by the graph engine's native
// back end (native_levenberg.cpp) and the motion-only solver (pose_only.cpp), so that both take
// the same steps.
#pragma once

#include <algorithm>
#include <cmath>

namespace pnpba::internal {

// lambda scaled by max(1/3, min(2/3, 1 - (2 rho - 1)^3)) for a step of gain ratio rho > 0.
inline double acceptedStepLambda(double lambda, double rho) {
  constexpr double kLowerScale = 1.0 / 3.0, kUpperScale = 2.0 / 3.0;
  const double alpha = 1.0 - std::pow(2.0 * rho - 1.0, 3);
  return lambda * std::max(kLowerScale, std::min(alpha, kUpperScale));
}

}  // namespace pnpba::internal
