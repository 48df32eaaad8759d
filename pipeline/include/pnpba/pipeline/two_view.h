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

// When a solved pose is still declared a failure: evidence that the two images do not show
// one rigid scene from one camera (no overlap, mirrored, rescaled). On the 36 TUM fr1_desk
// pairs the worst good pair has 254 inliers, ratio 0.80, chi2/inlier 1.6, 1-sigma 0.12 deg /
// 0.22 cm; pairs without a true overlap measured ratio <= 0.42 or sigma >= 0.35 deg / 0.89 cm.
// The thresholds sit between, about 2.5x from the good side (docs/two_view.md "Failure detection").
struct FailureRule {
  bool enabled = true;
  int min_inliers = 20;
  double min_inlier_ratio = 0.4;        // final inliers / 3D-2D pairs
  double max_chi2_per_inlier = 4.0;     // final robust chi2 / inliers (about 1 expected)
  double max_rotation_sigma_deg = 0.3;  // sqrt(trace) of the rotation covariance, 1 px noise
  double max_translation_sigma_cm = 0.6;
  // Empty when the result passes, else the failure message naming the evidence.
  std::string check(int pairs, int inliers, double chi2_final, bool covariance_ok,
                    const Eigen::Matrix<double, 6, 6>& covariance) const;
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
