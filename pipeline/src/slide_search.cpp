#include "pnpba/pipeline/slide_search.h"

#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace pnpba {

std::string SlideSearchOptions::validate() const {
  if (!(step_m >= 0) || !std::isfinite(step_m)) return "slide search: step must be finite and >= 0";
  if (steps < 1) return "slide search: steps must be >= 1";
  if (!(min_gain >= 0 && min_gain <= 1)) return "slide search: gain must be in [0, 1]";
  return "";
}

namespace {

// consistency_at of every pose, on the cores there are, each into its own slot: the values of
// one thread, in the poses' order.
std::vector<double> consistenciesAt(const std::vector<SE3Quat>& poses,
                                    const std::function<double(const SE3Quat&)>& consistency_at) {
  std::vector<double> c(poses.size());
  tbb::parallel_for(
      size_t{0}, poses.size(), [&](size_t i) { c[i] = consistency_at(poses[i]); },
      tbb::simple_partitioner());
  return c;
}

// T moved by a left translation of `metres` along camera 2's axis `axis`.
SE3Quat shiftedAlong(const SE3Quat& T, int axis, double metres) {
  Eigen::Matrix<double, 6, 1> shift = Eigen::Matrix<double, 6, 1>::Zero();
  shift[3 + axis] = metres;
  return SE3Quat::exp(shift) * T;
}

}  // namespace

SlideSeed findSlideSeed(const SE3Quat& T, double consistency,
                        const std::function<double(const SE3Quat&)>& consistency_at,
                        const SlideSearchOptions& options) {
  SlideSeed best;
  best.T = T;
  best.consistency = consistency;
  if (!(options.step_m > 0)) return best;
  // Every shift, axis by axis, -steps .. steps without 0; their consistencies are measured on
  // both cores (each into its own slot) and the best is taken in this order, so the answer is
  // that of one thread.
  std::vector<SE3Quat> shifted;
  for (int axis = 0; axis < 3; ++axis) {
    for (int k = -options.steps; k <= options.steps; ++k) {
      if (k != 0) shifted.push_back(shiftedAlong(T, axis, k * options.step_m));
    }
  }
  const std::vector<double> c = consistenciesAt(shifted, consistency_at);
  best.evaluations = static_cast<int>(shifted.size());
  for (size_t i = 0; i < shifted.size(); ++i) {
    if (c[i] > best.consistency) {
      best.consistency = c[i];
      best.T = shifted[i];
    }
  }
  best.found = best.consistency >= consistency + options.min_gain;
  if (!best.found) {
    best.T = T;
    best.consistency = consistency;
  }
  return best;
}

Eigen::Vector3d slideSigmas(const SE3Quat& T, double consistency,
                            const std::function<double(const SE3Quat&)>& consistency_at,
                            double probe_m, double consistency_sigma) {
  if (!(probe_m > 0) || !(consistency_sigma > 0)) return Eigen::Vector3d::Zero();
  std::vector<SE3Quat> shifted;
  for (int axis = 0; axis < 3; ++axis) {
    for (int side : {-1, 1}) shifted.push_back(shiftedAlong(T, axis, side * probe_m));
  }
  const std::vector<double> c = consistenciesAt(shifted, consistency_at);
  Eigen::Vector3d sigma;
  for (int axis = 0; axis < 3; ++axis) {
    double drop = consistency - std::max(c[2 * axis], c[2 * axis + 1]);
    if (!std::isfinite(drop)) drop = 0;  // nothing measured: as loose as a flat profile
    sigma[axis] = probe_m * std::sqrt(consistency_sigma / std::max(drop, 0.25 * consistency_sigma));
  }
  return sigma;
}

}  // namespace pnpba
