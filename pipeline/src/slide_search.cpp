#include "pnpba/pipeline/slide_search.h"

#include <cmath>

namespace pnpba {

std::string SlideSearchOptions::validate() const {
  if (!(step_m >= 0) || !std::isfinite(step_m)) return "slide search: step must be finite and >= 0";
  if (steps < 1) return "slide search: steps must be >= 1";
  if (!(min_gain >= 0 && min_gain <= 1)) return "slide search: gain must be in [0, 1]";
  return "";
}

SlideSeed findSlideSeed(const SE3Quat& T, double consistency,
                        const std::function<double(const SE3Quat&)>& consistency_at,
                        const SlideSearchOptions& options) {
  SlideSeed best;
  best.T = T;
  best.consistency = consistency;
  if (!(options.step_m > 0)) return best;
  for (int axis = 0; axis < 3; ++axis) {
    for (int k = -options.steps; k <= options.steps; ++k) {
      if (k == 0) continue;
      Eigen::Matrix<double, 6, 1> shift = Eigen::Matrix<double, 6, 1>::Zero();
      shift[3 + axis] = k * options.step_m;
      const SE3Quat shifted = SE3Quat::exp(shift) * T;
      const double c = consistency_at(shifted);
      ++best.evaluations;
      if (c > best.consistency) {
        best.consistency = c;
        best.T = shifted;
      }
    }
  }
  best.found = best.consistency >= consistency + options.min_gain;
  if (!best.found) {
    best.T = T;
    best.consistency = consistency;
  }
  return best;
}

}  // namespace pnpba
