// Private to the two-view driver's .cpp files: what the feature path leaves for the depth path,
// and the helpers both use.
#pragma once

#include <chrono>
#include <functional>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pnpba/pipeline/alignment_evidence.h"
#include "pnpba/pipeline/pose_fusion.h"
#include "pnpba/pipeline/two_view.h"
#include "rgbd_residuals.h"
#include "time_budget.h"

namespace pnpba {

// The stages' clock: each stage's time in TwoViewResult::times_ms.
using Clock = std::chrono::steady_clock;
inline double msSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// Everything the feature path computes, kept for the depth path's seeded refinement.
struct FeatureStage {
  Features f1, f2;
  PinholeCamera geometry;  // undistorted pixels: no distortion
  DepthOptions depth_options;
  PnpResult pnp;
  bool solved = false;  // a refined pose exists (it may still be refused)
};

// Keypoint i's pixel sigma, in the image's pixels: from its pyramid level (ORB:
// scale_factor^level; SIFT: 2^octave) where weight_by_octave, else 1, times the features'
// pixel_scale (more than 1 where the image was shrunk for detection: OrbOptions::max_pixels).
double keypointSigma(const Features& features, int i, const TwoViewOptions& options);

// Bundle adjustment from T_init over the pairs flagged in `use`; fills r's pose, chi2,
// covariance, inliers. False (r->failure set) when too few inliers survive. `alongside`, when
// given, runs on the other core while the covariance is modelled, only where the refinement
// succeeds: it may read r's pose and inliers and write r's fields the covariance model does not
// (the model writes the covariances, the variance factors and the calibration sensitivity).
bool refineInto(const FeatureStage& stage, const std::vector<char>& use, const SE3Quat& T_init,
                const cv::Mat& depth2, const TwoViewOptions& options, TwoViewResult* r,
                const std::function<void()>& alongside = {});

// Depth consistency of T with both depth images (-1 without depth 2).
double consistencyOf(const SE3Quat& T, const cv::Mat& depth1, const cv::Mat& depth2,
                     const Camera& camera);

// sqrt of the trace of the nominal covariance's rotation (deg) and translation (cm) blocks
// (TwoViewResult::nominal_covariance: the decisions' measure of precision); infinite without one.
std::pair<double, double> nominalSigmas(const TwoViewResult& r);

// The driver's decisions (two_view_decisions.cpp, whose header lists every case).
// Whether the depth path runs after the feature path gave `features`.
bool wantsDepthPath(const TwoViewResult& features, const cv::Mat& depth2,
                    const TwoViewOptions& options);
// Whether the feature path runs again with SIFT after ORB gave `orb`.
bool wantsSiftRetry(const TwoViewResult& orb, cv::Size image, const TwoViewOptions& options);
// The keypoints ORB must find in both images for the SIFT retry: sift_retry_min_keypoints at
// 640 x 480 or smaller, as many per pixel on a larger image, at most orb.num_features.
int siftRetryMinKeypoints(cv::Size image, const TwoViewOptions& options);
// The SIFT retry's options for images of this size: SIFT at twice the features, its scale space
// starting at the working resolution (workingScale).
TwoViewOptions siftRetryOptions(const TwoViewOptions& options, cv::Size image);
// Of two accepted poses (`agree`: within the pose tolerance), whether the depth path's wins.
bool preferDepthPose(const TwoViewResult& features, const TwoViewResult& depth, bool agree,
                     const TwoViewOptions& options);

// Where the feature BA's pose `features` and the depth path's agree (path both): *kept (the one
// preferDepthPose chose) gets the fusion (pose_fusion.h) of the feature BA's estimate with
// `dense`, the depths' and colours' own estimate of the depth path's pose (depthPath), its
// covariance, the fused calibration term and the fused pose's depth consistency. False, *kept
// untouched, where either is not such an estimate or a covariance does not fuse. `kept` may be
// `features`: it is written only after both are read.
bool fuseAgreeingPoses(const TwoViewResult& features, const std::optional<PoseEstimate>& dense,
                       const cv::Mat& depth1, const cv::Mat& depth2, const Camera& camera,
                       const TwoViewOptions& options, TwoViewResult* kept);

// One depth-path candidate: its seed, the aligned pose and the evidence for it.
struct DepthCandidate {
  std::string seed;   // "registration" or "features"
  SE3Quat T_seed, T;  // the seed and the aligned pose
  double consistency = -1;
  double fitness = -1;  // the registration's overlap (-1: not a registration)
  AlignmentEvidence evidence;
  int explained = 0;  // feature pairs within the gate
  // The registration's rank of a registration candidate (0: its best-supported pose; a rival
  // above), -1 for the feature pose.
  int rank = -1;
  // A twin one period along a repeat of the best-supported candidate (repeat_search.h), judged
  // as a rival by the repeat's own margin (depth_path_judging.h).
  bool repeat_twin = false;
  // Of those, the far end of a slide the depths leave free (RepeatTwin::free_slide).
  bool free_slide = false;
  // An accepted, precise feature pose that this candidate, aligned at quarter (or else half)
  // resolution, confirms (supported by the depths, not differing): it stands, and `evidence` is
  // not measured.
  bool confirms_features = false;
  // A registration candidate the depths contradicted at half resolution (depth_candidates.h): left
  // there, its evidence not measured; it is never returned.
  bool hopeless = false;
  // Where the alignment's coarse levels left it (down to half resolution), when they ran.
  std::optional<SE3Quat> T_coarse;
  // A candidate the coarse levels brought to where an earlier candidate's stopped
  // (TwoViewOptions::same_coarse_pose_deg): that candidate again, not aligned further or judged.
  bool duplicate = false;
  // An alignment of it reached the time budget's deadline and stopped there: neither aligned nor
  // measured, it cuts the pair (time_budget.h).
  bool out_of_time = false;
};

// The depth path and the SIFT retry work at 640 x 480's pixel count (15 % over it allowed):
// larger images are scaled down by this linear factor (1 for images within it). A sensor's
// higher resolution then costs the registration, the alignment, its evidence and the retry what
// 640 x 480 costs (the rendered and TUM pairs they were tuned on); the feature pairs keep their
// full-resolution pixels. Measured on the TUM fr3_cabinet key frames enlarged to 1280 x 960:
// depth-path pairs took 96 / 176 / 231 ms (p50 / p95 / max) at full resolution; on the sweep at
// 1.3 x (832 x 624, which halvings alone left as it was) the poor room's p95 was 135 ms and the
// rich room's max 265 ms, against 94 and 155 at 640 x 480.
constexpr int kWorkingPixels = 640 * 480;
double workingScale(cv::Size image);
// The SIFT retry's scale space starts at this share of the working resolution (its pixels: 72 %).
// Its time follows the pixels (detection and about 1300 descriptors on the rendered rooms), and
// at 60 degrees the retry's matches hold at this size: on the 3-seed sweep (rich, poor, cabinet,
// tiled; 432 pairs) the same ok / refused / wrong in every scene as at 1, the tiled room's p95
// 193 -> 141 ms and its max 218 -> 176; at 0.8 the rich room's pure 60-degree turn lost a
// pose, at 0.7 four (docs/two_view.md "Front end at large motion").
constexpr double kSiftRetryScale = 0.85;
// The images the depth path works on (workingScale): the pair's own, or, for larger ones, their
// grey in floats (the alignment reads no colour) halved as the alignment's pyramid halves them
// (grey by cv::pyrDown, depth every second pixel, pixel u' on the finer 2 u') while a halving
// stays at or above the working size, then resampled the rest of the way (grey by area, depth by
// the nearest pixel centre, pixel centres kept at (u' + 0.5) / s - 0.5), the intrinsics with them.
struct DepthPathView {
  cv::Mat image1, depth1, image2, depth2;
  Camera camera;  // of these images
  int halvings = 0;
  // The resampling after the halvings: working columns / halved columns, likewise rows (1: none).
  double scale_x = 1, scale_y = 1;
};
// The full-resolution pinhole `camera` as the view's images see it.
PinholeCamera viewPinhole(const PinholeCamera& camera, const DepthPathView& view);
DepthPathView depthPathView(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                            const cv::Mat& depth2, const Camera& camera);

// What an earlier depth-path call on the same pair (one estimateTwoView call: the
// conclusive-only pass, then the full one) built and may hand on: the image pyramid (the same
// images), and the feature candidate when the seed pose and the pairs are the same.
struct DepthCandidateCache {
  bool valid = false;
  size_t pairs = 0;
  DepthCandidate candidate;
  RecycledPyramid pyramid;            // built by the first call
  std::optional<DepthPathView> view;  // likewise
};

// The depth path (depth_path.cpp): pose candidates from the global depth registration and from
// the feature pose, each refined by the coloured alignment, judged by evidence the alignment
// did not optimise. Returns the depth path's result (ok or refused, with its failure rule);
// `features` is the feature path's result it starts from. conclusive_only: only the feature
// candidate, and ok only when it is conclusive (no global registration runs). `dense`, where
// given, gets the depths' and colours' own estimate of the returned pose, without the feature
// pairs that joined its alignment (AlignmentEvidence::dense_step): the estimate independent of
// the feature BA's; empty where the depth path returns no aligned candidate. Each alignment and
// the registration start only where `budget` allows them; where it cut one, the result is not
// ok, its failure the budget's message, and the driver refuses the pair. depth1_kept, where
// given, is frame 1's store of its depth's description for the registration
// (registerDepthImages).
TwoViewResult depthPath(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                        const cv::Mat& depth2, const Camera& camera, const TwoViewOptions& options,
                        const TwoViewResult& features, const FeatureStage& stage,
                        bool conclusive_only, TimeBudget* budget, LaterFeatures* depth1_kept,
                        DepthCandidateCache* cache = nullptr,
                        std::optional<PoseEstimate>* dense = nullptr);

}  // namespace pnpba
