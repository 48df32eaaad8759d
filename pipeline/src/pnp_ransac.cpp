#include "pnpba/pipeline/pnp_ransac.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <random>

#include "pnpba/core/error.h"

namespace pnpba {

namespace {

// EPnP needs 4 points; 5 (as OpenCV's solvePnPRansac draws) make the minimal solve stable
// against near-degenerate samples at a small cost in samples needed.
constexpr int kSampleSize = 5;

bool solveEpnp(const Correspondences& pairs, const std::vector<int>& subset, const cv::Matx33d& K,
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
  return "";
}

std::vector<double> reprojectionErrors2(const Correspondences& pairs, const SE3Quat& T_21,
                                        const PinholeCamera& camera) {
  std::vector<double> e2(pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) {
    const Eigen::Vector3d P = T_21.map(pairs[i].X_1);
    e2[i] = P.z() > 0 ? (camera.project(P) - pairs[i].uv_2).squaredNorm()
                      : std::numeric_limits<double>::infinity();
  }
  return e2;
}

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
  const cv::Matx33d K(camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
  const double threshold2 = options.threshold_px * options.threshold_px;
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;

  if (method == PnpMethod::kIterative) {
    if (!solveEpnp(pairs, all, K, cv::SOLVEPNP_ITERATIVE, &result.T_21)) {
      result.failure = "solvePnP failed";
      return result;
    }
    // No threshold (the textbook keeps every pair), but a pose that puts points behind camera 2
    // is not a pose of this scene.
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

  std::mt19937_64 rng(options.seed);
  int best = -1;
  double best_error = std::numeric_limits<double>::infinity();
  SE3Quat best_T;
  int needed = options.max_iterations;
  std::vector<int> sample(kSampleSize);
  for (int it = 0; it < needed; ++it) {
    ++result.iterations;
    // Partial Fisher-Yates: kSampleSize distinct indices.
    for (int k = 0; k < kSampleSize; ++k) {
      std::uniform_int_distribution<int> pick(k, n - 1);
      std::swap(all[k], all[pick(rng)]);
      sample[k] = all[k];
    }
    SE3Quat T;
    if (!solveEpnp(pairs, sample, K, cv::SOLVEPNP_EPNP, &T)) continue;
    const std::vector<double> e2 = reprojectionErrors2(pairs, T, camera);
    int inliers = 0;
    double error = 0;
    for (double e : e2) {
      if (e < threshold2) {
        ++inliers;
        error += e;
      }
    }
    if (inliers > best || (inliers == best && error < best_error)) {
      best = inliers;
      best_error = error;
      best_T = T;
      // Samples needed to draw an all-inlier one with the requested confidence; computed in
      // double and clamped, since for few inliers it exceeds any integer.
      const double w = static_cast<double>(inliers) / n;
      const double p_good = std::pow(w, kSampleSize);
      double samples = options.max_iterations;
      if (p_good >= 1.0) {
        samples = it + 1;
      } else if (p_good > 0) {
        samples = std::log(1 - options.confidence) / std::log1p(-p_good);
      }
      needed = static_cast<int>(std::min<double>(std::ceil(samples), options.max_iterations));
    }
  }
  if (best < options.min_inliers) {
    result.failure = std::to_string(std::max(best, 0)) + " RANSAC inliers < " +
                     std::to_string(options.min_inliers) + " required";
    return result;
  }
  // EPnP refit on the inliers; kept when it does not lose inliers.
  std::vector<char> inlier;
  countInliers(reprojectionErrors2(pairs, best_T, camera), threshold2, &inlier);
  std::vector<int> inlier_ids;
  for (int i = 0; i < n; ++i)
    if (inlier[i]) inlier_ids.push_back(i);
  SE3Quat refit;
  if (solveEpnp(pairs, inlier_ids, K, cv::SOLVEPNP_EPNP, &refit)) {
    std::vector<char> refit_inlier;
    const int m =
        countInliers(reprojectionErrors2(pairs, refit, camera), threshold2, &refit_inlier);
    if (m >= best) {
      best_T = refit;
      inlier = refit_inlier;
      best = m;
    }
  }
  result.ok = true;
  result.T_21 = best_T;
  result.inlier = inlier;
  result.num_inliers = best;
  return result;
}

}  // namespace pnpba
