// The two-view RGB-D pose: image 1 + depth 1 + image 2 (+ depth 2) + camera -> T_21.
//   ORB in both images (two threads) -> matching -> depth lookup -> 3D-2D pairs
//   -> EPnP in RANSAC (or the textbook's iterative PnP) -> bundle adjustment (BundleMode).
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pnpba/features/correspondences.h"
#include "pnpba/features/matching.h"
#include "pnpba/pipeline/camera.h"
#include "pnpba/pipeline/pnp_ransac.h"
#include "pnpba/pipeline/pose_refinement.h"

namespace pnpba {

// The evidence a solved pose is judged on.
struct PoseEvidence {
  int pairs = 0;               // 3D-2D pairs offered to RANSAC
  int inliers = 0;             // after BA
  double chi2_final = 0;       // robust chi2 of the final BA graph
  int competitor_inliers = 0;  // pairs a rival RANSAC pose explains and this one does not
  double inlier_coverage = 1;  // image-2 convex hull area of the inliers / of all pairs
  bool covariance_ok = false;
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();  // [w, v]
};

// Which rule refused a pose ("" when none did) and the message naming the evidence.
struct FailureVerdict {
  std::string rule;  // inliers, inlier_ratio, chi2, ambiguous, local_fit, degenerate, max_sigma
  std::string message;
  bool refused() const { return !rule.empty(); }
};

// When a solved pose is still refused: evidence that it may be WRONG or undetermined, never
// mere imprecision (DESIGN.md 5b). A wide baseline, far points or few features give a large
// covariance, which is reported, not refused, unless the user sets a precision limit.
struct FailureRule {
  bool enabled = true;
  int min_inliers = 20;
  double min_inlier_ratio = 0.4;  // final inliers / 3D-2D pairs
  // Robust chi2 per inlier of the final graph. Inliers are gated at chi2(2 dof, 95%) on image
  // 2, so a correct pose gives about the residual dof per inlier (2-3 in rgbd mode); far more
  // means the depths disagree with the pose (wrong depth scale, a non-rigid scene).
  double max_chi2_per_inlier = 4.0;
  // A rival RANSAC pose explaining other pairs, as many as this fraction of the inliers: the
  // data do not decide between the two.
  double max_competitor_ratio = 0.6;
  // Inliers confined to a small patch of the matched area while most pairs disagree: a pose
  // that fits locally (a non-rigid or rescaled image, a wrong camera) rather than the scene.
  // Refused when the inlier ratio is below local_fit_ratio and the coverage below this.
  double min_inlier_coverage = 0.3;
  double local_fit_ratio = 0.6;
  // 1-sigma along the worst rotation / translation direction beyond which the pose is
  // undetermined: at 2 sigma it may be off by more than 10 deg / 50 cm, the "wrong" limits.
  double max_undetermined_sigma_deg = 5.0;
  double max_undetermined_sigma_m = 0.25;
  // The user's precision limits on the 1-sigma (sqrt of the trace of each block); 0 = off.
  double max_sigma_deg = 0;
  double max_sigma_cm = 0;
  std::string validate() const;  // empty when valid
  FailureVerdict check(const PoseEvidence& evidence) const;
};

struct TwoViewOptions {
  OrbOptions orb;
  MatchOptions matching;
  DepthOptions depth;  // depth.depth_scale is taken from the Camera
  bool undistort = true;
  // Weight each pixel observation by its ORB pyramid level (sigma = scale_factor^level), as
  // ORB-SLAM does; off: every pixel has sigma 1 px.
  bool weight_by_octave = true;
  PnpMethod pnp = PnpMethod::kEpnpRansac;
  RansacOptions ransac;
  RefinementOptions refinement;  // refinement.mode: the BA mode (default rgbd)
  FailureRule failure_rule;

  // The textbook program's exact front end: 500 ORB features, its match filter, every depth
  // != 0, no undistortion, SOLVEPNP_ITERATIVE on all pairs, the textbook BA graph.
  static TwoViewOptions textbookPreset();
  std::string validate() const;  // empty when valid
};

struct TwoViewCounts {
  int keypoints1 = 0, keypoints2 = 0, matches = 0, pairs = 0, inliers = 0;
  int competitor_inliers = 0;  // pairs a rival RANSAC pose explains and the estimate does not
};

struct StageTimes {
  double features_ms = 0, matching_ms = 0, depth_ms = 0, pnp_ms = 0, ba_ms = 0, total_ms = 0;
};

struct TwoViewResult {
  bool ok = false;
  std::string failure;  // when !ok: which stage and how many, e.g. "4 3D-2D pairs < 6 required"
  SE3Quat T_init;       // PnP pose
  SE3Quat T_21;         // refined: camera 2 from camera 1
  double chi2_initial = 0, chi2_final = 0;
  int ba_iterations = 0;
  std::string solver;
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();  // [w, v]
  bool covariance_ok = false;
  double inlier_coverage = 0;  // image-2 convex hull area of the inliers / of all pairs
  std::string failure_rule;    // the FailureRule that refused the pose ("" otherwise)
  TwoViewCounts counts;
  StageTimes times_ms;
  // For drawing and export.
  std::vector<cv::KeyPoint> keypoints1, keypoints2;
  Correspondences pairs;
  std::vector<char> inlier;  // per pair: RANSAC and BA inlier
};

// Names the inputs in error messages (file paths in the CLIs).
struct TwoViewInputNames {
  std::string image1 = "image 1", image2 = "image 2", depth1 = "depth 1", depth2 = "depth 2";
};

// Throws Error "<name>: <problem>" unless the images are 8-bit grey/colour of one size (one
// camera took both), the depths 16-bit single-channel with some valid depth and of their
// image's size (depth2 may be empty).
void checkTwoViewInputs(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                        const cv::Mat& depth2, const TwoViewInputNames& names = {});

// Throws Error for bad input (empty images, depth not 16-bit single channel, size mismatch);
// returns ok = false when the pose cannot be estimated.
TwoViewResult estimateTwoView(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                              const cv::Mat& depth2, const Camera& camera,
                              const TwoViewOptions& options);

}  // namespace pnpba
