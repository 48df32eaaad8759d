#include "pnpba/pipeline/two_view.h"

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "pnpba/core/error.h"

namespace pnpba {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

void checkImage(const cv::Mat& image, const std::string& what) {
  if (image.empty()) throw Error(what + ": image is empty or unreadable");
  if (image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3)) {
    throw Error(what + ": expected an 8-bit grey or colour image");
  }
}

std::string sizeText(const cv::Mat& m) {
  return std::to_string(m.cols) + "x" + std::to_string(m.rows);
}

// Area of the convex hull of the inliers' image-2 pixels over that of all pairs' (1 when
// there are fewer than three points of either).
double inlierCoverage(const Correspondences& pairs, const std::vector<char>& inlier) {
  std::vector<cv::Point2f> all, in;
  for (size_t i = 0; i < pairs.size(); ++i) {
    const cv::Point2f p(static_cast<float>(pairs[i].uv_2.x()),
                        static_cast<float>(pairs[i].uv_2.y()));
    all.push_back(p);
    if (inlier[i]) in.push_back(p);
  }
  if (in.size() < 3 || all.size() < 3) return 1.0;
  std::vector<cv::Point2f> hull_all, hull_in;
  cv::convexHull(all, hull_all);
  cv::convexHull(in, hull_in);
  const double area_all = cv::contourArea(hull_all);
  return area_all > 0 ? cv::contourArea(hull_in) / area_all : 1.0;
}

}  // namespace

void checkTwoViewInputs(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                        const cv::Mat& depth2, const TwoViewInputNames& names) {
  checkImage(image1, names.image1);
  checkImage(image2, names.image2);
  if (image2.size() != image1.size()) {
    throw Error(names.image2 + ": size " + sizeText(image2) + " differs from " + names.image1 +
                "'s " + sizeText(image1) + " (both views must come from one camera)");
  }
  checkDepthImage(depth1, names.depth1);
  if (depth1.size() != image1.size()) {
    throw Error(names.depth1 + ": size " + sizeText(depth1) + " differs from " + names.image1 +
                "'s " + sizeText(image1));
  }
  if (!depth2.empty()) {
    checkDepthImage(depth2, names.depth2);
    if (depth2.size() != image2.size()) {
      throw Error(names.depth2 + ": size " + sizeText(depth2) + " differs from " + names.image2 +
                  "'s " + sizeText(image2));
    }
  }
}

std::string FailureRule::validate() const {
  if (min_inliers < 0) return "failure rule: min inliers must be >= 0";
  if (!(min_inlier_ratio >= 0 && min_inlier_ratio <= 1)) {
    return "failure rule: min inlier ratio must be in [0, 1]";
  }
  for (double v : {max_chi2_per_inlier, max_competitor_ratio, max_undetermined_sigma_deg,
                   max_undetermined_sigma_m}) {
    if (!(v > 0)) return "failure rule: chi2, competitor and undetermined limits must be > 0";
  }
  if (!(max_sigma_deg >= 0) || !(max_sigma_cm >= 0) || !std::isfinite(max_sigma_deg) ||
      !std::isfinite(max_sigma_cm)) {
    return "max sigma limits must be >= 0 (0: off)";
  }
  return "";
}

FailureVerdict FailureRule::check(const PoseEvidence& e) const {
  if (!enabled) return {};
  char text[200];
  auto refuse = [&text](const char* rule) { return FailureVerdict{rule, text}; };
  if (e.inliers < min_inliers) {
    std::snprintf(text, sizeof text, "%d inliers < %d required", e.inliers, min_inliers);
    return refuse("inliers");
  }
  const double ratio = e.pairs > 0 ? static_cast<double>(e.inliers) / e.pairs : 0.0;
  if (ratio < min_inlier_ratio) {
    std::snprintf(text, sizeof text, "inlier ratio %.2f (%d of %d pairs) < %.2f", ratio, e.inliers,
                  e.pairs, min_inlier_ratio);
    return refuse("inlier_ratio");
  }
  if (e.chi2_final / e.inliers > max_chi2_per_inlier) {
    std::snprintf(text, sizeof text, "chi2 per inlier %.2f > %.2f", e.chi2_final / e.inliers,
                  max_chi2_per_inlier);
    return refuse("chi2");
  }
  if (e.competitor_inliers > max_competitor_ratio * e.inliers) {
    std::snprintf(
        text, sizeof text,
        "ambiguous: a rival pose explains %d pairs the estimate does not (it has %d inliers)",
        e.competitor_inliers, e.inliers);
    return refuse("ambiguous");
  }
  if (ratio < local_fit_ratio && e.inlier_coverage < min_inlier_coverage) {
    std::snprintf(text, sizeof text,
                  "local fit: the inliers cover %.0f %% of the matched area and %.0f %% of the "
                  "pairs",
                  100.0 * e.inlier_coverage, 100.0 * ratio);
    return refuse("local_fit");
  }
  if (e.covariance_ok) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> rot(e.covariance.topLeftCorner<3, 3>());
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> trans(e.covariance.bottomRightCorner<3, 3>());
    const double worst_deg = std::sqrt(std::max(rot.eigenvalues()(2), 0.0)) * 180.0 / M_PI;
    const double worst_m = std::sqrt(std::max(trans.eigenvalues()(2), 0.0));
    if (worst_deg > max_undetermined_sigma_deg || worst_m > max_undetermined_sigma_m) {
      std::snprintf(text, sizeof text,
                    "degenerate geometry: 1-sigma along the worst direction %.1f deg, %.1f cm",
                    worst_deg, worst_m * 100.0);
      return refuse("degenerate");
    }
    const double rot_sigma = std::sqrt(e.covariance.topLeftCorner<3, 3>().trace()) * 180.0 / M_PI;
    const double trans_sigma = std::sqrt(e.covariance.bottomRightCorner<3, 3>().trace()) * 100.0;
    if ((max_sigma_deg > 0 && rot_sigma > max_sigma_deg) ||
        (max_sigma_cm > 0 && trans_sigma > max_sigma_cm)) {
      std::snprintf(text, sizeof text,
                    "pose less precise than asked: 1-sigma %.2f deg, %.2f cm (limits %.2f deg, "
                    "%.2f cm)",
                    rot_sigma, trans_sigma, max_sigma_deg, max_sigma_cm);
      return refuse("max_sigma");
    }
  }
  return {};
}

TwoViewOptions TwoViewOptions::textbookPreset() {
  TwoViewOptions o;
  o.orb.num_features = 500;
  o.orb.levels = 8;
  o.matching.filter = MatchFilter::kTextbook;
  o.depth.min_depth = 0.0;
  o.depth.max_depth = std::numeric_limits<double>::max();
  o.depth.round_to_nearest = false;
  o.undistort = false;
  o.weight_by_octave = false;
  o.pnp = PnpMethod::kIterative;
  o.refinement.mode = BundleMode::kTextbook;
  o.refinement.iterations = 100;
  return o;
}

std::string TwoViewOptions::validate() const {
  for (const std::string& p : {orb.validate(), matching.validate(), depth.validate(),
                               ransac.validate(), refinement.validate(), failure_rule.validate()}) {
    if (!p.empty()) return p;
  }
  return "";
}

TwoViewResult estimateTwoView(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                              const cv::Mat& depth2, const Camera& camera,
                              const TwoViewOptions& options) {
  const auto start = Clock::now();
  std::string problem = options.validate();
  if (problem.empty()) problem = camera.validate();
  if (!problem.empty()) throw Error(problem);
  checkTwoViewInputs(image1, depth1, image2, depth2);
  if (camera.width > 0 && (image1.cols != camera.width || image1.rows != camera.height)) {
    throw Error("image 1: size differs from the camera's");
  }
  DepthOptions depth_options = options.depth;
  depth_options.depth_scale = camera.depth_scale;

  TwoViewResult r;
  auto t = Clock::now();
  auto [f1, f2] = detectOrbPair(image1, image2, options.orb);
  r.times_ms.features_ms = msSince(t);
  r.counts.keypoints1 = static_cast<int>(f1.keypoints.size());
  r.counts.keypoints2 = static_cast<int>(f2.keypoints.size());
  r.keypoints1 = f1.keypoints;
  r.keypoints2 = f2.keypoints;

  t = Clock::now();
  const std::vector<cv::DMatch> matches =
      matchDescriptors(f1.descriptors, f2.descriptors, options.matching);
  r.times_ms.matching_ms = msSince(t);
  r.counts.matches = static_cast<int>(matches.size());

  t = Clock::now();
  r.pairs = buildCorrespondences(f1, f2, matches, depth1, camera.pinhole, depth_options,
                                 options.undistort);
  r.times_ms.depth_ms = msSince(t);
  r.counts.pairs = static_cast<int>(r.pairs.size());
  auto finish = [&](const std::string& failure) {
    r.failure = failure;
    r.times_ms.total_ms = msSince(start);
    return r;
  };
  if (r.counts.keypoints1 == 0 || r.counts.keypoints2 == 0) {
    return finish("no keypoints in image " + std::string(r.counts.keypoints1 == 0 ? "1" : "2"));
  }

  t = Clock::now();
  PinholeCamera geometry = camera.pinhole;
  geometry.distortion = {};  // pairs are undistorted (or distortion is ignored)
  const PnpResult pnp = estimatePnp(r.pairs, geometry, options.pnp, options.ransac);
  r.times_ms.pnp_ms = msSince(t);
  if (!pnp.ok) return finish(pnp.failure);
  r.T_init = pnp.T_21;
  r.counts.inliers = pnp.num_inliers;

  t = Clock::now();
  std::vector<PointPair> ba_pairs;
  std::vector<size_t> ba_index;
  for (size_t i = 0; i < r.pairs.size(); ++i) {
    if (!pnp.inlier[i]) continue;
    PointPair p{r.pairs[i].X_1, r.pairs[i].uv_2, r.pairs[i].uv_1};
    if (options.weight_by_octave) {
      p.sigma_1 = std::pow(options.orb.scale_factor, f1.keypoints[r.pairs[i].keypoint_1].octave);
      p.sigma_2 = std::pow(options.orb.scale_factor, f2.keypoints[r.pairs[i].keypoint_2].octave);
    }
    if (!depth2.empty()) {
      const cv::Point2f& raw2 = f2.keypoints[r.pairs[i].keypoint_2].pt;
      if (auto z2 = depthAt(depth2, raw2.x, raw2.y, depth_options)) p.depth_2 = *z2;
    }
    ba_pairs.push_back(p);
    ba_index.push_back(i);
  }
  const Refinement ba = refinePose(ba_pairs, pnp.T_21, geometry, options.refinement);
  r.times_ms.ba_ms = msSince(t);
  r.inlier.assign(r.pairs.size(), 0);
  for (size_t k = 0; k < ba_index.size(); ++k) r.inlier[ba_index[k]] = ba.inlier[k];
  r.counts.inliers = ba.num_inliers;
  r.T_21 = ba.T_21;
  r.chi2_initial = ba.chi2_initial;
  r.chi2_final = ba.chi2_final;
  r.ba_iterations = ba.iterations;
  r.solver = ba.solver;
  r.covariance = ba.covariance;
  r.covariance_ok = ba.covariance_ok;
  if (ba.num_inliers < options.ransac.min_inliers) {
    return finish(std::to_string(ba.num_inliers) + " inliers after BA < " +
                  std::to_string(options.ransac.min_inliers) + " required");
  }
  r.counts.competitor_inliers = pnp.competitor_inliers;
  r.inlier_coverage = inlierCoverage(r.pairs, r.inlier);
  PoseEvidence evidence;
  evidence.pairs = r.counts.pairs;
  evidence.inliers = ba.num_inliers;
  evidence.chi2_final = ba.chi2_final;
  evidence.competitor_inliers = pnp.competitor_inliers;
  evidence.inlier_coverage = r.inlier_coverage;
  evidence.covariance_ok = ba.covariance_ok;
  evidence.covariance = ba.covariance;
  const FailureVerdict verdict = options.failure_rule.check(evidence);
  if (verdict.refused()) {
    r.failure_rule = verdict.rule;
    return finish(verdict.message);
  }
  if (!r.T_21.to_homogeneous_matrix().allFinite()) return finish("bundle adjustment diverged");
  r.ok = true;
  r.times_ms.total_ms = msSince(start);
  return r;
}

}  // namespace pnpba
