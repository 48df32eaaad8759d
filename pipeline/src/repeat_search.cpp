#include "pnpba/pipeline/repeat_search.h"

#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace pnpba {

std::string RepeatSearchOptions::validate() const {
  if (!(max_shift_m >= 0) || !std::isfinite(max_shift_m)) {
    return "repeat search: max shift must be finite and >= 0";
  }
  if (max_shift_m == 0) return "";  // no search
  if (!(min_shift_m > 0) || !(min_shift_m <= max_shift_m)) {
    return "repeat search: min shift must be > 0 and <= max shift";
  }
  if (!(step_m > 0) || !std::isfinite(step_m)) return "repeat search: step must be > 0";
  if (!(consistency_margin >= 0 && consistency_margin <= 1)) {
    return "repeat search: consistency margin must be in [0, 1]";
  }
  if (!(min_agree_ratio > 0 && min_agree_ratio <= 1)) {
    return "repeat search: agree ratio must be in (0, 1]";
  }
  if (!(min_dip >= 0 && min_dip <= 1)) return "repeat search: dip must be in [0, 1]";
  if (!(free_slide_m >= 0) || !std::isfinite(free_slide_m)) {
    return "repeat search: free slide must be finite and >= 0";
  }
  if (stride < 1) return "repeat search: stride must be >= 1";
  if (max_twins < 1) return "repeat search: max twins must be >= 1";
  if (!(rival_consistency_margin >= 0 && rival_consistency_margin <= 1)) {
    return "repeat search: rival consistency margin must be in [0, 1]";
  }
  return "";
}

namespace {

// Camera 1's x, y and z and the diagonals between x and z: a repeat seen face on, from above or
// below, along the view (a corridor) or at 45 degrees.
std::vector<Eigen::Vector3d> searchDirections() {
  const double h = std::sqrt(0.5);
  return {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(),
          Eigen::Vector3d(h, 0, h), Eigen::Vector3d(h, 0, -h)};
}

// T with camera 1's scene shifted by d: X2 = R (X1 + d) + t.
SE3Quat sceneShifted(const SE3Quat& T, const Eigen::Vector3d& d) {
  return SE3Quat(T.rotation(), T.translation() + T.rotation() * d);
}

}  // namespace

std::vector<RepeatTwin> findRepeatTwins(
    const SE3Quat& T, const std::function<DepthConsistency(const SE3Quat&)>& measure,
    const RepeatSearchOptions& options, const std::vector<Eigen::Vector3d>& loose) {
  std::vector<RepeatTwin> twins;
  if (!(options.max_shift_m > 0)) return twins;
  const DepthConsistency own = measure(T);
  if (own.agree == 0) return twins;
  // Every shift, ray by ray (a direction and a sign), nearest first; measured on both cores, each
  // into its own slot, and read in this order, so the answer is that of one thread.
  std::vector<Eigen::Vector3d> directions = searchDirections();
  for (const Eigen::Vector3d& d : loose) {
    if (d.norm() > 0) directions.push_back(d.normalized());
  }
  const int steps =
      static_cast<int>(std::floor((options.max_shift_m - options.min_shift_m) / options.step_m)) +
      1;
  std::vector<Eigen::Vector3d> shifts;
  for (const Eigen::Vector3d& direction : directions) {
    for (double sign : {1.0, -1.0}) {
      for (int i = 0; i < steps; ++i) {
        shifts.push_back(sign * (options.min_shift_m + i * options.step_m) * direction);
      }
    }
  }
  std::vector<DepthConsistency> c(shifts.size());
  tbb::parallel_for(
      size_t{0}, shifts.size(), [&](size_t i) { c[i] = measure(sceneShifted(T, shifts[i])); },
      tbb::simple_partitioner());
  // Along each ray, first a slide the depths leave free: every shift out to free_slide_m keeps
  // the pose's consistency; the first shift that far is its twin.
  auto keeps = [&](const DepthConsistency& d) {
    return d.consistency() >= own.consistency() - options.consistency_margin &&
           d.agree >= options.min_agree_ratio * own.agree;
  };
  for (size_t ray = 0; ray < 2 * directions.size() && options.free_slide_m > 0; ++ray) {
    for (int i = 0; i < steps; ++i) {
      const size_t k = ray * steps + i;
      if (!keeps(c[k])) break;
      if (shifts[k].norm() >= options.free_slide_m - 1e-9) {
        twins.push_back({sceneShifted(T, shifts[k]), shifts[k], c[k].consistency(),
                         static_cast<double>(c[k].agree) / own.agree, /*free_slide=*/true});
        break;
      }
    }
  }
  // Then the most consistent shift beyond a dip: a repeat's twin is a second peak, where a slide
  // along a plain plane only falls away from the pose.
  std::vector<size_t> peaks;
  for (size_t ray = 0; ray < 2 * directions.size(); ++ray) {
    double lowest = own.consistency(), peak_consistency = -1;
    size_t peak = shifts.size();
    for (int i = 0; i < steps; ++i) {
      const size_t k = ray * steps + i;
      const double consistency = c[k].consistency();
      if (consistency >= lowest + options.min_dip && consistency > peak_consistency &&
          c[k].agree >= options.min_agree_ratio * own.agree) {
        peak = k;
        peak_consistency = consistency;
      }
      lowest = std::min(lowest, consistency);
    }
    if (peak < shifts.size()) peaks.push_back(peak);
  }
  // Each peak looked at a quarter and half a step either side: on the grid it may lie up to half
  // a step off its crest, where an obliquely seen face has already left the tolerance.
  const double offsets[] = {-0.5, -0.25, 0.25, 0.5};
  std::vector<Eigen::Vector3d> nearby;
  for (size_t k : peaks) {
    for (double f : offsets) {
      nearby.push_back(shifts[k] + f * options.step_m * shifts[k].normalized());
    }
  }
  std::vector<DepthConsistency> nearby_c(nearby.size());
  tbb::parallel_for(
      size_t{0}, nearby.size(),
      [&](size_t i) { nearby_c[i] = measure(sceneShifted(T, nearby[i])); },
      tbb::simple_partitioner());
  for (size_t p = 0; p < peaks.size(); ++p) {
    Eigen::Vector3d shift = shifts[peaks[p]];
    DepthConsistency best = c[peaks[p]];
    for (size_t j = 0; j < 4; ++j) {
      if (nearby_c[4 * p + j].consistency() > best.consistency()) {
        best = nearby_c[4 * p + j];
        shift = nearby[4 * p + j];
      }
    }
    const double ratio = static_cast<double>(best.agree) / own.agree;
    if (best.consistency() >= own.consistency() - options.consistency_margin &&
        ratio >= options.min_agree_ratio) {
      twins.push_back({sceneShifted(T, shift), shift, best.consistency(), ratio});
    }
  }
  std::stable_sort(twins.begin(), twins.end(), [](const RepeatTwin& a, const RepeatTwin& b) {
    return a.consistency > b.consistency;
  });
  // One twin per place: a diagonal's best may be the same shift an axis found. One free slide's
  // far end shows the slide as well as both would, at one alignment (10-20 ms).
  std::vector<RepeatTwin> kept;
  bool free_slide_kept = false;
  for (const RepeatTwin& t : twins) {
    const bool near_kept = std::any_of(kept.begin(), kept.end(), [&](const RepeatTwin& k) {
      return (k.shift - t.shift).norm() < options.min_shift_m;
    });
    if (near_kept || (t.free_slide && free_slide_kept)) continue;
    free_slide_kept = free_slide_kept || t.free_slide;
    kept.push_back(t);
    if (static_cast<int>(kept.size()) == options.max_twins) break;
  }
  return kept;
}

}  // namespace pnpba
