// The two-view RGB-D pose: image 1 + depth 1 + image 2 (+ depth 2) + camera -> T_21.
//   ORB in both images (two threads) -> matching -> depth lookup -> 3D-2D pairs
//   -> EPnP in RANSAC (or the textbook's iterative PnP) -> bundle adjustment (BundleMode).
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "pnpba/features/correspondences.h"
#include "pnpba/features/matching.h"
#include "pnpba/pipeline/alignment_evidence.h"
#include "pnpba/pipeline/camera.h"
#include "pnpba/pipeline/covariance_model.h"
#include "pnpba/pipeline/depth_registration.h"
#include "pnpba/pipeline/failure_rule.h"
#include "pnpba/pipeline/frame_features.h"
#include "pnpba/pipeline/pnp_ransac.h"
#include "pnpba/pipeline/pose_refinement.h"
#include "pnpba/pipeline/repeat_search.h"
#include "pnpba/pipeline/rgbd_alignment.h"
#include "pnpba/pipeline/slide_search.h"

namespace pnpba {

// When the depth-only registration (depth_registration.h) runs; it needs depth 2.
//   kAuto    when the feature path fails, is refused, or its pose disagrees with the depths
//   kOff     never (features only)
//   kAlways  on every pair, and the pose the data support more is kept
enum class DepthPath { kAuto, kOff, kAlways };
const char* toString(DepthPath path);
DepthPath parseDepthPath(const std::string& name);  // "auto", "off", "always"; throws Error

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
  DepthPath depth_path = DepthPath::kAuto;
  DepthRegistrationOptions registration;
  // Depth consistency (depth_consistency.h) below which a feature pose is cross-checked by the
  // depth path (kAuto). Refusal is the failure rule's min_depth_consistency.
  // Correct feature poses measured 0.987-0.997 on TUM fr1_desk and >= 0.98 on rendered rooms.
  double cross_check_below_consistency = 0.95;
  // ... or whose 1-sigma (sqrt of each block's trace) exceeds these: an imprecise feature pose
  // (few features, all far or on one plane) is cross-checked by the scene's whole geometry,
  // and the more precise of two agreeing poses is kept. TUM fr1_desk's worst: 0.12 deg, 0.22 cm.
  double cross_check_sigma_deg = 0.3;
  double cross_check_sigma_cm = 2.0;
  // A registration must explain at least this fraction of the down-sampled depth-1 points.
  double min_registration_fitness = 0.2;
  // The depth path refines every candidate pose (registration, features) by the direct RGB-D
  // alignment (rgbd_alignment.h); off: the registration's geometry alone.
  bool align_rgbd = true;
  RgbdAlignmentOptions rgbd_alignment;
  AlignmentEvidenceOptions alignment_evidence;
  // How the reported covariance is built from the estimators' information (covariance_model.h):
  // the fit's variance factor and the calibration's uncertainty.
  CovarianceModelOptions covariance;
  // A depth-path pose is refused when its aligned images agree less than this (zero-mean NCC
  // of co-visible intensities, alignment_evidence.h). Correct depth-path poses: >= 0.75 on the
  // rendered sweep (rich room at 60 degrees and 2 m the lowest), >= 0.79 on TUM fr3_cabinet; a
  // flipped fit of the rendered cabinet scene 0.59 ...
  double min_photometric_agreement = 0.7;
  // ... or when another candidate that the depths support and that differs from it agrees in
  // colour within this margin: the data do not decide between the two.
  double rival_photometric_margin = 0.02;
  // Depth consistencies this far apart decide between candidates.
  double clear_consistency_margin = 0.02;
  // A depth-path pose that fewer than failure_rule.min_inliers feature pairs support rests on
  // the depths alone and needs this consistency (failure_rule.min_registration_consistency
  // otherwise). Correct depth-only poses: 0.98-1.00 on rendered rooms, 0.96-0.997 on TUM
  // fr3_cabinet; wrong ones 0.75-0.81 on rendered rooms, 0.90-0.94 on fr3_cabinet.
  double min_depth_only_consistency = 0.95;
  // The depth path keeps an aligned feature pose without running the global registration when
  // its depth consistency and photometric agreement reach these and it explains at least half
  // of the feature pairs (and ransac.min_inliers): cheap evidence before costly evidence.
  double conclusive_consistency = 0.98;
  double conclusive_photometric_agreement = 0.9;
  // ... or, where most pairs are wrong matches (a wide baseline's, a repeated texture's twins),
  // when it explains at least this many and no rival RANSAC pose explains more than
  // failure_rule.max_competitor_ratio as many others (0: half the pairs always). Over the
  // rendered sweep and its tiled room (3 seeds, 432 pairs, 106 refused feature poses aligned)
  // none of the 53 more than 10 deg or 50 cm off reached the colour bar (the twins' poses, 1-1.5
  // m along the tiles, also failed the depths: 0.14-0.25); 31 correct ones reached both with
  // 18-41 % of the pairs explained and are now kept there (docs/two_view.md).
  int conclusive_min_explained_pairs = 20;
  // A depth-path candidate the depths support but below conclusive_consistency is stepped along
  // camera 2's axes (slide_search.h); where a shift gains consistency it is aligned again from
  // there, and the new pose replaces it when the depths support it better by the same margin.
  SlideSearchOptions slide_search;
  // The depth path's chosen pose, where the depths alone carry it, is shifted along camera 1's
  // axes (and the direction its covariance is loosest along) by 0.3-2 m; a shift the depths
  // support nearly as well (a structure whose geometry repeats, or a slide along plain planes
  // they leave free out to free_slide_m) is aligned as one more candidate, and the evidence
  // then either separates the two or refuses the pair as a rival (repeat_search.h).
  // max_shift_m 0: no search; free_slide_m 0: repeats only.
  RepeatSearchOptions repeat_search;
  // A depth-path candidate (the feature pose or a registration pose) whose depth consistency,
  // aligned down to half resolution, lies this far below the lower support bar
  // (min_depth_only_consistency, failure_rule.min_registration_consistency) is not aligned at
  // full resolution nor judged: it can never be returned. Over 714 candidates (the sweep, its
  // noisier cabinet and poor room, the fr3_cabinet key frames) full resolution raised a
  // registration candidate's consistency by at most 0.14; the work skipped is 8-12 ms a
  // registration candidate and 7-26 ms a refused feature pose the depths reject (the poor
  // room's refusals). >= 1: every candidate is aligned in full.
  double hopeless_consistency_gap = 0.3;
  // A depth-path candidate whose coarse levels (down to half resolution) end within this angle
  // (deg) and this distance (m) of where an earlier candidate's ended is that candidate again:
  // it is not aligned at full resolution, searched or judged a second time (10-30 ms at 640 x 480).
  // On the 3-seed sweep and the fr3_cabinet key frames, candidates that ended their coarse
  // levels up to 1.2 deg / 2.4 cm apart ended their full alignment within 0.12 deg / 0.2 cm of
  // each other; the nearest that did not (8 deg / 58 cm apart) ended 4.6 deg / 6 cm apart. Both
  // bounds sit well inside posesDiffer's 5 deg / 5 cm, so no rival is lost by it. 0: every
  // candidate is aligned in full.
  double same_coarse_pose_deg = 2.0;
  double same_coarse_pose_m = 0.03;
  // The global registration's candidates (up to 8 rival poses, depth_registration.h) beyond
  // this many are screened before they are aligned: each over the registration's overlap floor
  // is aligned at its two coarsest levels alone (80 x 60 and 160 x 120, 1-3 ms), and only this
  // many with the highest depth consistency there go on to the alignment and evidence above
  // (10-30 ms each). On the fr3_cabinet key frames five and eight apart: 1, 27 of 45 within
  // 2 deg / 5 cm; 2 (a rival for the evidence to compare), 26 at 25-30 ms more a pair; every
  // candidate (0), 27 at 3-4x the alignment's time; none wrong. 0: every candidate goes on.
  int aligned_registration_candidates = 1;
  // A depth-path pose must explain at least this share of frame 1 (depth-1 samples landing on
  // depth 2's surface; alignment_evidence.h): a sliver proves nothing. Correct poses of the
  // rendered sweep go down to 0.16 at 60-degree turns.
  double min_overlap = 0.05;
  // ... and a pose the depths alone carry (fewer than failure_rule.min_inliers feature pairs in
  // support), this much. In a scene of a few large planes a slide along a wall or a flip
  // between faces fits as well as the truth wherever the views overlap, and only a large
  // overlap leaves it no room: over the rendered cabinet at four depth sensors (quantised or
  // smooth, k = 0.001-0.0025) and both rooms, 9 of 34 depth-only poses under 0.25 were wrong
  // (slides of 2-4 m, flips of 90-180 degrees), 1 of 274 above it.
  double min_depth_only_overlap = 0.25;
  // ... and such a pose from a rival of the registration's best-supported pose (chosen among up
  // to 8, aligned_registration_candidates), this much: the more poses tried, the likelier one
  // fits a few planes by chance. The rendered cabinet under a smoother depth (k = 0.0015) gave
  // two slides of 3.8 and 4.3 m along its wall over 30 % and 26 % of frame 1; right rival poses
  // measured 0.27-0.80 there and on the sweep, 0.36-0.88 on TUM fr3_cabinet.
  double min_rival_depth_only_overlap = 0.35;
  // With at least this many feature pairs, a depth-path pose that explains fewer than this
  // fraction of them is refused (features_disagree).
  int features_judge_pairs = 20;
  double min_explained_fraction = 0.05;
  // When the ORB feature path fails or is refused, run it once more with SIFT (twice the
  // features) before the depth path: SIFT holds at rotations where ORB's matches run out
  // (wide-baseline sweep, rich texture at 60 degrees: 14/18 within 2 deg / 5 cm against ORB's
  // 2/18) but costs several times ORB's time, so it runs only where ORB gave nothing
  // (docs/two_view.md "Front end at large motion").
  bool retry_with_sift = true;
  // ...and only where ORB found texture: at least this many keypoints in both images (a third of
  // ORB's 1500). Below it SIFT finds too few as well and the depth path decides. Measured
  // 2026-11-24: with ORB under 500 keypoints the retry found no pose on any of 25 pairs (the
  // rendered poor room at 30-60 degrees, 3 seeds, ORB 74-480 keypoints; two fr3_cabinet pairs,
  // 211-253) and cost 50-90 ms on each; where it found poses (the rich room at 60 degrees)
  // ORB had its full 1500. At 200 (the threshold before) it also cost 60-170 ms on 3 of 68
  // rendered-cabinet and fr3_cabinet pairs the depth path solved without it. The count is
  // 640 x 480's: a larger image needs as many per pixel (1500 at 1280 x 720), or ORB's whole
  // budget (orb.num_features), which only texture fills. At 1280 x 720 the rendered poor room
  // gives ORB 550-1100 keypoints, where the retry cost 20-36 ms a pair and found nothing.
  int sift_retry_min_keypoints = 500;
  // ...and not where the depths contradict ORB's pose (consistency below the failure rule's
  // min_depth_consistency, whichever rule refused it) while at least this many inliers hold it
  // (0: retried all the same): that is no matching failure, and SIFT matches the same motion.
  // Measured 2026-11-29 (moving_object_bench: a box moving on its own through the rendered
  // room): the retry ran on 16 of 48 rich-room pairs whose ORB pose 130-490 inliers held at
  // depth consistency 0.61-0.75, cost 46-81 ms each, and twice returned the box's motion (20 deg
  // / 28 cm and 60 cm off) once its own pose reached 0.90. On the three-seed wide-baseline
  // sweep the retry ran 15 times, after ORB poses of at most 47 inliers; on the RealSense-like
  // sweep and every TUM set not at all. In the tiled room (ORB's twin-shifted poses) the depth
  // path settles what the retry had: every cell's ok / refused / wrong the same (88 / 20 / 0).
  int sift_retry_max_contradicted_inliers = 100;
  // One estimate's wall-clock budget (ms; 0: none), for a caller that needs an answer at a frame
  // rate (33 ms at 30 Hz). Each optional stage after the feature path (the depth path's check
  // or alignment of the feature pose, the SIFT retry, the global registration, each registration
  // candidate or repeat twin) starts only when its expected time (an average of what it took
  // before in this process) fits in what is left; a pair a stage did not fit into is refused (rule
  // "time_budget"), never answered with less evidence. So each pair gets the answer it gets
  // without a budget, or that refusal. The feature path itself always runs; the RGB-D alignment
  // stops at the deadline between two of its steps (refused likewise), and the other stages,
  // once started, run to their end. With a budget the answer depends on the machine's speed: the
  // one exception to "the same input gives the same pose" (docs/two_view.md "A time budget").
  double time_budget_ms = 0;

  // The textbook program's exact front end: 500 ORB features, its match filter, every depth
  // != 0, no undistortion, SOLVEPNP_ITERATIVE on all pairs, the textbook BA graph.
  static TwoViewOptions textbookPreset();
  std::string validate() const;  // empty when valid
};

struct TwoViewCounts {
  int keypoints1 = 0, keypoints2 = 0, matches = 0, pairs = 0, inliers = 0;
  int competitor_inliers = 0;  // pairs a rival RANSAC pose explains and the estimate does not
  // The depth path's candidates it aligned (the feature pose's, the registration's), and the
  // ones among the registration's found at half resolution to be an earlier one again
  // (TwoViewOptions::same_coarse_pose_deg), not counted in the first.
  int depth_candidates = 0, depth_duplicates = 0;
};

struct StageTimes {
  // ba_ms: the feature BA and its covariance model, with what is measured beside the model at
  // the refined pose (the inliers' area and the depth consistency).
  double features_ms = 0, matching_ms = 0, depth_ms = 0, pnp_ms = 0, ba_ms = 0, total_ms = 0;
  double sift_retry_ms = 0;  // the SIFT retry, whole (detection to BA), when it ran
  // The depth path's global registration, when it ran, without the opening of its plugin.
  double registration_ms = 0;
  // A process's first registration whose options take one of Open3D's steps opens its plugin
  // first (25-180 ms, once; depthPathOpensOpen3d); preloadDepthRegistration() takes it out of
  // the first pair. In total_ms too: that pair waited. 0 with the default options.
  double plugin_load_ms = 0;
  // The depth path's RGB-D alignment of its candidates: the image pyramid, each alignment and
  // its evidence.
  double alignment_ms = 0;
  // The depth consistency of the feature path's refined pose (its depths against depth 2, both
  // ways). It runs on the other core beside the covariance model, so it is part of ba_ms's wall
  // time, not added to it; the depth path's own consistencies are in alignment_ms.
  double depth_consistency_ms = 0;

  // Every stage with its report name (the JSON's "timings_ms" keys), in the order they run;
  // total not included.
  std::vector<std::pair<const char*, double>> named() const {
    return {{"features", features_ms},
            {"matching", matching_ms},
            {"depth", depth_ms},
            {"pnp", pnp_ms},
            {"ba", ba_ms},
            {"depth_consistency", depth_consistency_ms},
            {"sift_retry", sift_retry_ms},
            {"plugin_load", plugin_load_ms},
            {"registration", registration_ms},
            {"alignment", alignment_ms}};
  }
};

struct TwoViewResult {
  bool ok = false;
  // Which path produced T_21: "features", "depth-registration", or "both" (they agreed; where
  // the depth path's own alignment ran, T_21 and its covariance are the two fused,
  // CovarianceModelOptions::fuse_agreeing_poses).
  std::string path;
  // Path "both" only: whether T_21 and its covariance are the two paths' fusion (pose_fusion.h)
  // rather than the kept one's own (a precise feature pose merely confirmed, or fusion off).
  bool fused = false;
  std::string detector;  // the features behind the pose: "orb" or "sift" (the retry)
  std::string failure;   // when !ok: which stage and how many, e.g. "4 3D-2D pairs < 6 required"
  SE3Quat T_init;        // PnP pose
  SE3Quat T_21;          // refined: camera 2 from camera 1
  double chi2_initial = 0, chi2_final = 0;
  int ba_iterations = 0;
  std::string solver;
  // Of T_21, [w, v] (left perturbation), as covariance_model.h builds it: the estimator's
  // information scaled by the fit, plus the calibration's and the motion's uncertainty.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool covariance_ok = false;
  // What the failure rule and --max-sigma-* judge: `covariance` with the variance factors read
  // as at least 1 (a fit that looks better than the nominal noise must not talk a weak geometry
  // into passing) and without the motion term (how far real sensors stray, not how firmly this
  // pair's geometry pins the pose).
  Eigen::Matrix<double, 6, 6> judged_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  // The estimator's inverse information at the nominal noise alone: how firmly the geometry
  // pins the pose. Which path runs and which pose wins are decided on it, so that the
  // calibration's sigmas move no decision.
  Eigen::Matrix<double, 6, 6> nominal_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  // The calibration term's source: the pose shift per unit error of fx, fy (relative), cx, cy
  // (px) and the depth scale (relative); `covariance` holds it with the model's sigmas.
  Eigen::Matrix<double, 6, 5> calibration_sensitivity = Eigen::Matrix<double, 6, 5>::Zero();
  // The fit's variance factors of the pixel and the depth noise, each with the residuals'
  // correlation inflation, within the model's bounds (1: not scaled).
  double variance_factor = 1;
  double depth_variance_factor = 1;
  // The depth path's slide term (covariance_model.h, C_slide): the translation 1-sigma along
  // camera 2's x, y and z that the depth consistency leaves a depth-path pose (m); zero where the
  // returned pose is not the depth path's own.
  Eigen::Vector3d slide_sigma_m = Eigen::Vector3d::Zero();
  double inlier_coverage = 0;         // image-2 convex hull area of the inliers / of all pairs
  double depth_consistency = -1;      // of T_21 with both depth images (-1: not measured)
  double registration_fitness = -1;   // of the depth path, when it ran
  double photometric_agreement = -1;  // of a depth-path pose's images (-1: not measured)
  double overlap = -1;       // share of frame 1 a depth-path pose explains (-1: not measured)
  std::string failure_rule;  // the FailureRule that refused the pose ("" otherwise)
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
  std::string camera = "the camera";
};

// Throws Error "<name>: <problem>" unless the images are 8-bit grey/colour of one size (one
// camera took both), the depths 16-bit single-channel with some valid depth and of their
// image's size (depth2 may be empty).
void checkTwoViewInputs(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                        const cv::Mat& depth2, const TwoViewInputNames& names = {});

// Throws Error "<image1>: size WxH differs from <camera>'s WxH (...)" when the camera knows
// the image size it was calibrated at (Camera::width, height) and image 1 has another: its
// intrinsics would not describe these pixels.
void checkCameraSize(const cv::Mat& image1, const Camera& camera,
                     const TwoViewInputNames& names = {});

// True where an estimate with these options may open Open3D's plugin: its depth path may run
// and its registration takes one of Open3D's own steps (DepthRegistrationOptions: the global
// search open3d-ransac or fast, ICP iterations). The defaults do not: a loop with them has
// nothing to preload (preloadDepthRegistration()).
bool depthPathOpensOpen3d(const TwoViewOptions& options);

// Throws Error for bad input (empty images, depth not 16-bit single channel, size mismatch);
// returns ok = false when the pose cannot be estimated. A depth value of 0 or 65535 is no depth.
// features1 / features2, where given, are the images' features found once by describeFrame
// with options.orb (frame_features.h): their detection is skipped and the answer is the same.
// Features of another image or found with other options throw Error.
TwoViewResult estimateTwoView(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                              const cv::Mat& depth2, const Camera& camera,
                              const TwoViewOptions& options,
                              const FrameFeatures* features1 = nullptr,
                              const FrameFeatures* features2 = nullptr);

}  // namespace pnpba
