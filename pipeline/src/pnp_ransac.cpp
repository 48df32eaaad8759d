#include "pnpba/pipeline/pnp_ransac.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <random>

#include "pnpba/core/error.h"
#include "pnpba/pipeline/epnp.h"
#include "reprojection_scorer.h"

namespace pnpba {

namespace {

// EPnP needs 4 points; 5 (as OpenCV's solvePnPRansac draws) make the minimal solve stable
// against near-degenerate samples at a small cost in samples needed.
constexpr int kSampleSize = 5;

// cv::solvePnP on the listed pairs (the textbook preset's SOLVEPNP_ITERATIVE).
bool solveOpenCv(const Correspondences& pairs, const std::vector<int>& subset, const cv::Matx33d& K,
                 int flags, SE3Quat* T) {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (int i : subset) {
    object.emplace_back(pairs[i].X_1.x(), pairs[i].X_1.y(), pairs[i].X_1.z());
    image.emplace_back(pairs[i].uv_2.x(), pairs[i].uv_2.y());
  }
  cv::Mat rvec, tvec;
  try {
    if (!cv::solvePnP(object, image, K, cv::noArray(), rvec, tvec, false, flags)) return false;
  } catch (const cv::Exception&) {
    return false;  // degenerate sample
  }
  cv::Matx33d R;
  cv::Rodrigues(rvec, R);
  Eigen::Matrix3d Re;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) Re(r, c) = R(r, c);
  const Eigen::Vector3d t(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  if (!Re.allFinite() || !t.allFinite()) return false;
  *T = SE3Quat(Re, t);
  return true;
}

int countInliers(const std::vector<double>& e2, double threshold2, std::vector<char>* inlier) {
  int n = 0;
  inlier->assign(e2.size(), 0);
  for (size_t i = 0; i < e2.size(); ++i) {
    if (e2[i] < threshold2) {
      (*inlier)[i] = 1;
      ++n;
    }
  }
  return n;
}

}  // namespace

std::string RansacOptions::validate() const {
  if (!std::isfinite(threshold_px) || !(threshold_px > 0)) return "ransac threshold must be > 0";
  if (!(confidence > 0 && confidence < 1)) return "ransac confidence must be in (0, 1)";
  if (max_iterations < 1) return "ransac iterations must be >= 1";
  if (min_inliers < 4) return "min inliers must be >= 4";
  if (num_threads < 1) return "ransac threads must be >= 1";
  return "";
}

std::vector<double> reprojectionErrors2(const Correspondences& pairs, const SE3Quat& T_21,
                                        const PinholeCamera& camera) {
  std::vector<double> e2;
  ReprojectionScorer(pairs, camera).squaredErrors(T_21, &e2);
  return e2;
}

namespace {

// The textbook's SOLVEPNP_ITERATIVE on every pair: no threshold, but a pose that puts points
// behind camera 2 is not a pose of this scene.
PnpResult solveIterativeOnAll(const Correspondences& pairs, const PinholeCamera& camera,
                              const cv::Matx33d& K, const RansacOptions& options) {
  PnpResult result;
  const int n = static_cast<int>(pairs.size());
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  if (!solveOpenCv(pairs, all, K, cv::SOLVEPNP_ITERATIVE, &result.T_21)) {
    result.failure = "solvePnP failed";
    return result;
  }
  result.num_inliers = countInliers(reprojectionErrors2(pairs, result.T_21, camera),
                                    std::numeric_limits<double>::infinity(), &result.inlier);
  if (result.num_inliers < options.min_inliers) {
    result.failure = "solvePnP pose puts " + std::to_string(n - result.num_inliers) + " of " +
                     std::to_string(n) + " points behind camera 2";
    return result;
  }
  result.ok = true;
  return result;
}

// Samples needed to draw an all-inlier sample with the requested confidence; computed in double
// and clamped, since for few inliers it exceeds any integer.
int neededSamples(int inliers, int n, int done, const RansacOptions& options) {
  const double w = static_cast<double>(inliers) / n;
  const double p_good = std::pow(w, kSampleSize);
  double samples = options.max_iterations;
  if (p_good >= 1.0) {
    samples = done;
  } else if (p_good > 0) {
    samples = std::log(1 - options.confidence) / std::log1p(-p_good);
  }
  return static_cast<int>(std::min<double>(std::ceil(samples), options.max_iterations));
}

struct Hypothesis {
  int inliers = -1;
  double error = std::numeric_limits<double>::infinity();  // sum of inlier squared errors
  SE3Quat T;
};

// The strongest hypotheses seen, mutually different poses, kept for the ambiguity check.
class Contenders {
 public:
  void offer(const Hypothesis& h) {
    for (Hypothesis& c : kept_) {
      if (!posesDiffer(c.T, h.T)) {
        if (h.inliers > c.inliers) c = h;
        return;
      }
    }
    kept_.push_back(h);
    std::sort(kept_.begin(), kept_.end(),
              [](const Hypothesis& a, const Hypothesis& b) { return a.inliers > b.inliers; });
    if (kept_.size() > kMax) kept_.pop_back();
  }
  // Most pairs that a kept pose explains and the winner (inlier flags) does not.
  int strongestRival(const ReprojectionScorer& scorer, double threshold2,
                     const std::vector<char>& winner_inlier) const {
    int best = 0;
    std::vector<double> e2;
    for (const Hypothesis& c : kept_) {
      scorer.squaredErrors(c.T, &e2);
      int own = 0;
      for (size_t i = 0; i < e2.size(); ++i) own += e2[i] < threshold2 && !winner_inlier[i];
      best = std::max(best, own);
    }
    return best;
  }

 private:
  static constexpr size_t kMax = 16;
  std::vector<Hypothesis> kept_;
};

// One sample's pose and its score (inliers < 0 when the sample is degenerate).
Hypothesis solveSample(const Correspondences& pairs, const PinholeCamera& camera,
                       const ReprojectionScorer& scorer, const int* sample, double threshold2) {
  Hypothesis h;
  if (!solveEpnp(pairs, sample, kSampleSize, camera, &h.T)) return h;
  h.inliers = 0;
  h.error = 0;
  thread_local std::vector<double> e2;  // one per TBB worker: no allocation per sample
  scorer.squaredErrors(h.T, &e2);
  for (double e : e2) {
    if (e < threshold2) {
      ++h.inliers;
      h.error += e;
    }
  }
  return h;
}

// EPnP on random minimal samples, scored by inlier count then inlier error; adaptive stop.
// The samples are drawn in order from the seeded generator whatever their poses turn out to be,
// so past the first kAlone, while more than a block is still needed, a block of them is solved
// on TBB's workers (num_threads > 1) and then read in order: the adaptive stop sees the same scores
// in the same order as a one-at-a-time loop, and the samples solved past it are dropped. The result
// is the same for any thread count; a pair whose matches are mostly wrong (all 500 samples
// drawn) takes 0.6-0.7 of its time on two cores.
Hypothesis ransacSearch(const Correspondences& pairs, const PinholeCamera& camera,
                        const ReprojectionScorer& scorer, const RansacOptions& options,
                        int* iterations, Contenders* contenders) {
  constexpr int kAlone = 32;  // most pairs stop within these (fr1_desk: 10-30 samples)
  constexpr int kBlock = 32;  // a thread's start-up is under a tenth of its half
  const int n = static_cast<int>(pairs.size());
  const double threshold2 = options.threshold_px * options.threshold_px;
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  std::mt19937_64 rng(options.seed);
  Hypothesis best;
  int needed = options.max_iterations;
  std::vector<int> samples(kSampleSize * kBlock);
  std::vector<Hypothesis> solved(kBlock);
  int it = 0;
  while (it < needed) {
    const bool in_block = options.num_threads > 1 && it >= kAlone && needed - it > kBlock;
    const int count = in_block ? kBlock : 1;
    for (int b = 0; b < count; ++b) {
      // Partial Fisher-Yates: kSampleSize distinct indices.
      for (int k = 0; k < kSampleSize; ++k) {
        std::uniform_int_distribution<int> pick(k, n - 1);
        std::swap(all[k], all[pick(rng)]);
        samples[kSampleSize * b + k] = all[k];
      }
    }
    auto solveRange = [&](int begin, int end) {
      for (int b = begin; b < end; ++b) {
        solved[b] = solveSample(pairs, camera, scorer, &samples[kSampleSize * b], threshold2);
      }
    };
    if (in_block) {
      // The block in chunks of kChunk samples on TBB's workers, each sample's hypothesis its own
      // whichever thread solves it: where the second core is shared with other work, halves left
      // the block waiting on the slower one.
      constexpr int kChunk = 4;
      tbb::parallel_for(
          tbb::blocked_range<int>(0, count, kChunk),
          [&](const tbb::blocked_range<int>& r) { solveRange(r.begin(), r.end()); },
          tbb::simple_partitioner());
    } else {
      solveRange(0, count);
    }
    for (int b = 0; b < count && it < needed; ++b, ++it) {
      ++*iterations;
      const Hypothesis& h = solved[b];
      if (h.inliers < 0) continue;
      if (h.inliers >= options.min_inliers) contenders->offer(h);
      if (h.inliers > best.inliers || (h.inliers == best.inliers && h.error < best.error)) {
        best = h;
        needed = neededSamples(best.inliers, n, it + 1, options);
      }
    }
  }
  return best;
}

}  // namespace

PnpResult estimatePnp(const Correspondences& pairs, const PinholeCamera& camera, PnpMethod method,
                      const RansacOptions& options) {
  const std::string problem = options.validate();
  if (!problem.empty()) throw Error(problem);
  PnpResult result;
  const int n = static_cast<int>(pairs.size());
  if (n < options.min_inliers) {
    result.failure =
        std::to_string(n) + " 3D-2D pairs < " + std::to_string(options.min_inliers) + " required";
    return result;
  }
  if (method == PnpMethod::kIterative) {
    const cv::Matx33d K(camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
    return solveIterativeOnAll(pairs, camera, K, options);
  }

  const ReprojectionScorer scorer(pairs, camera);
  Contenders contenders;
  const Hypothesis best =
      ransacSearch(pairs, camera, scorer, options, &result.iterations, &contenders);
  if (best.inliers < options.min_inliers) {
    result.failure = std::to_string(std::max(best.inliers, 0)) + " RANSAC inliers < " +
                     std::to_string(options.min_inliers) + " required";
    return result;
  }
  // EPnP refit on the inliers; kept when it does not lose inliers.
  const double threshold2 = options.threshold_px * options.threshold_px;
  result.T_21 = best.T;
  std::vector<double> e2;
  scorer.squaredErrors(best.T, &e2);
  result.num_inliers = countInliers(e2, threshold2, &result.inlier);
  std::vector<int> inlier_ids;
  for (int i = 0; i < n; ++i)
    if (result.inlier[i]) inlier_ids.push_back(i);
  SE3Quat refit;
  if (solveEpnp(pairs, inlier_ids.data(), static_cast<int>(inlier_ids.size()), camera, &refit)) {
    std::vector<char> refit_inlier;
    scorer.squaredErrors(refit, &e2);
    const int m = countInliers(e2, threshold2, &refit_inlier);
    if (m >= result.num_inliers) {
      result.T_21 = refit;
      result.inlier = refit_inlier;
      result.num_inliers = m;
    }
  }
  result.competitor_inliers = contenders.strongestRival(scorer, threshold2, result.inlier);
  result.ok = true;
  return result;
}

bool posesDiffer(const SE3Quat& a, const SE3Quat& b) {
  const double angle = Eigen::AngleAxisd(a.rotation() * b.rotation().inverse()).angle();
  const double scale = std::max(a.translation().norm(), b.translation().norm());
  return angle > 5.0 * M_PI / 180.0 ||
         (a.translation() - b.translation()).norm() > std::max(0.05, 0.2 * scale);
}

}  // namespace pnpba
