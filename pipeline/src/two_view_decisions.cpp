// The two-view pose's decisions: which path runs, which pose wins, which refusal fires. Each is
// a small function here or named below; the driver (two_view.cpp, estimateTwoView) calls them
// in this order, cheap evidence before costly evidence.
//
//   after the ORB feature path        decision                                    where
//   ------------------------------    ------------------------------------------  ----------------
//   accepted, precise, depths agree   done: path "features"                       wantsDepthPath
//   refused only by --max-sigma-*     done: refused, rule max_sigma (the user's   wantsDepthPath
//                                     limit; the pose is not in doubt)
//   accepted but imprecise or the     cross-check it on the depth path            wantsDepthPath
//   depths disagree (< 0.95), or      (depth_path.cpp); a precise accepted pose
//   refused, or no pose               its alignment at quarter (else half)
//                                     resolution agrees with and the depths
//                                     support stands there (no full-resolution
//                                     level, no evidence)
//   a pose was solved but refused     align it alone; done when conclusive        depth_path.cpp
//                                     (depths >= 0.98, colour >= 0.9, half the    (conclusive_only)
//                                     pairs explained, or 20 where no rival
//                                     RANSAC pose has 0.6 of their support);
//                                     ~30 ms
//   still no accepted pose, ORB       retry with SIFT at twice the features, at   wantsSiftRetry
//   found >= 500 keypoints in both    0.85 of 640 x 480's resolution; its pose    retryFeatures
//   (per 640 x 480 pixels), and its   is kept when accepted, or refused but with
//   pose was not one >= 100 inliers   more inliers than ORB's (the depth path's
//   hold and the depths contradict    seed)
//   still not settled                 the depth path: the feature pose aligned;   depth_path.cpp
//                                     the global registration only when that
//                                     one is not conclusive
//   two accepted poses that agree     the feature BA's (path "both"), unless it   preferDepthPose
//                                     is imprecise and the aligned one is not;
//                                     the kept one then takes the two estimates'  two_view_fusion
//                                     fused pose and covariance where the depth
//                                     path's own alignment ran
//   two accepted poses that differ    the one the depths support clearly more     preferDepthPose
//                                     (consistency + 0.02), else the more precise
//   nothing accepted                  refused: both paths' reasons, the depth
//                                     path's rule (table in depth_path_judging.h)
//   a stage after the feature path    refused, rule time_budget, whatever the      time_budget.h
//   would not fit time_budget_ms      stages before it had (off by default)
#include <algorithm>
#include <cmath>

#include "two_view_stages.h"

namespace pnpba {

bool wantsDepthPath(const TwoViewResult& features, const cv::Mat& depth2,
                    const TwoViewOptions& options) {
  if (depth2.empty() || options.depth_path == DepthPath::kOff) return false;
  // A pose refused only for the user's precision limit is not in doubt.
  if (features.failure_rule == "max_sigma") return false;
  if (options.depth_path == DepthPath::kAlways || !features.ok) return true;
  const auto [sigma_deg, sigma_cm] = nominalSigmas(features);
  return (features.depth_consistency >= 0 &&
          features.depth_consistency < options.cross_check_below_consistency) ||
         sigma_deg > options.cross_check_sigma_deg || sigma_cm > options.cross_check_sigma_cm;
}

// Which of two accepted poses to keep: `features` (the feature path's) or `depth` (the depth
// path's). Poses that agree: the feature BA's, pixel-accurate when features are plentiful,
// unless it is imprecise and the registration is more precise. Poses that disagree: the one the
// depths support clearly more, else the more precise.
bool preferDepthPose(const TwoViewResult& features, const TwoViewResult& depth, bool agree,
                     const TwoViewOptions& options) {
  const auto [f_deg, f_cm] = nominalSigmas(features);
  const auto [d_deg, d_cm] = nominalSigmas(depth);
  if (agree) {
    const bool imprecise =
        f_deg > options.cross_check_sigma_deg || f_cm > options.cross_check_sigma_cm;
    return imprecise && d_cm < f_cm;
  }
  constexpr double kClearlyMoreConsistent = 0.02;
  if (depth.depth_consistency > features.depth_consistency + kClearlyMoreConsistent) return true;
  if (features.depth_consistency > depth.depth_consistency + kClearlyMoreConsistent) return false;
  return d_cm < f_cm;
}

bool wantsSiftRetry(const TwoViewResult& orb, cv::Size image, const TwoViewOptions& options) {
  // A pose many inliers hold that the depths contradict is matched already, whichever rule
  // refused it first: something moved on its own, or the depths are off, and SIFT would match
  // the same motion.
  const bool matched_but_contradicted =
      options.sift_retry_max_contradicted_inliers > 0 &&
      orb.counts.inliers >= options.sift_retry_max_contradicted_inliers &&
      orb.depth_consistency >= 0 &&
      orb.depth_consistency < options.failure_rule.min_depth_consistency;
  return !orb.ok && !matched_but_contradicted && options.retry_with_sift &&
         options.orb.detector == Detector::kOrb &&
         std::min(orb.counts.keypoints1, orb.counts.keypoints2) >=
             siftRetryMinKeypoints(image, options);
}

// sift_retry_min_keypoints per 640 x 480 pixels on a larger image, at most ORB's budget.
int siftRetryMinKeypoints(cv::Size image, const TwoViewOptions& options) {
  const double pixels = static_cast<double>(image.width) * image.height;
  const double per_pixel =
      options.sift_retry_min_keypoints * std::max(1.0, pixels / kWorkingPixels);
  return static_cast<int>(std::min<double>(std::ceil(per_pixel), options.orb.num_features));
}

// The SIFT retry's options: SIFT at twice the features. At 60 degrees 3000 SIFT features found
// 14/18 rich-texture poses within 2 deg / 5 cm where 1500 found 9/18 (wide-baseline sweep,
// features only). Its scale space starts at the image's own resolution, at half OpenCV's
// contrast threshold: on the 3-seed sweep the same ok / refused / wrong in every scene as on the
// image doubled (rich 106 / 2 / 0), the rich room's 60-degree cells 211-390 -> 75-249 ms at the
// median; at OpenCV's threshold it finds about 1100 keypoints there, and 105 / 3 / 0.
TwoViewOptions siftRetryOptions(const TwoViewOptions& options, cv::Size image) {
  TwoViewOptions o = options;
  o.orb.detector = Detector::kSift;
  o.orb.num_features = 2 * options.orb.num_features;
  // At most 640 x 480's work (170-210 ms at 1280 x 960 from the image's own resolution; 111-136
  // ms at 832 x 624 against 58 at 640 x 480), and of that kSiftRetryScale, within the octaves
  // SIFT's options allow: whole octaves, then a fraction of one.
  const double scale = kSiftRetryScale * workingScale(image);
  int octave = 0;
  while (octave < 4 && scale * (2 << octave) <= 1 + 1e-9) ++octave;
  o.orb.sift_first_octave = octave;
  o.orb.sift_octave_fraction = std::min(1.0, std::max(0.5 + 1e-6, scale * (1 << octave)));
  o.orb.sift_contrast_threshold = 0.02;
  // A retry's pose rests on few matches across a wide baseline: the depths must support it as
  // they must a depth-only pose (correct retry poses measured 0.96-1.00 on the sweep, 0.92 under
  // twice its depth noise; one 6.5 deg / 37 cm off, 0.65). Refused here, the pair goes on to
  // the depth path as with any refused feature pose.
  o.failure_rule.min_depth_consistency =
      std::max(o.failure_rule.min_depth_consistency, o.failure_rule.min_registration_consistency);
  return o;
}

}  // namespace pnpba
