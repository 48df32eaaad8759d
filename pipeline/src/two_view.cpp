// The two-view driver: estimateTwoView's stages in order (the feature path, the cheap
// alignment check, the SIFT retry, the depth path), each decision in two_view_decisions.cpp
// and the feature BA with its covariance in feature_refinement.cpp.
#include "pnpba/pipeline/two_view.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "pnpba/core/error.h"
#include "pnpba/core/heap_retention.h"
#include "pnpba/features/depth_lookup.h"
#include "pnpba/pipeline/depth_consistency.h"
#include "two_view_stages.h"

namespace pnpba {

namespace {

// The callers' features of image 1 and image 2 (describeFrame), where given.
struct GivenFeatures {
  const FrameFeatures* first = nullptr;
  const FrameFeatures* second = nullptr;
};

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

// A keypoint's pixel sigma from the pyramid level it was found on: scale_factor^level for ORB;
// for SIFT, 2^octave from OpenCV's packed octave field (at least 1 px, the upsampled octave -1
// included); for AKAZE, 2^octave (its octaves halve the image).
double levelSigma(const cv::KeyPoint& k, const OrbOptions& orb) {
  if (orb.detector == Detector::kAkaze) return std::ldexp(1.0, std::max(0, k.octave));
  if (orb.detector == Detector::kSift) {
    int octave = k.octave & 255;
    if (octave >= 128) octave -= 256;
    return std::max(1.0, std::ldexp(1.0, octave));
  }
  return std::pow(orb.scale_factor, k.octave);
}

}  // namespace

double keypointSigma(const Features& features, int i, const TwoViewOptions& options) {
  const double level =
      options.weight_by_octave ? levelSigma(features.keypoints[i], options.orb) : 1.0;
  return features.pixel_scale * level;
}

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

void checkCameraSize(const cv::Mat& image1, const Camera& camera, const TwoViewInputNames& names) {
  if (camera.width <= 0 || (image1.cols == camera.width && image1.rows == camera.height)) return;
  throw Error(names.image1 + ": size " + sizeText(image1) + " differs from " + names.camera +
              "'s " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
              " (the size its intrinsics were calibrated at)");
}

TwoViewOptions TwoViewOptions::textbookPreset() {
  TwoViewOptions o;
  o.orb.num_features = 500;
  o.orb.levels = 8;
  o.orb.max_pixels = 0;  // ORB on the image as it is, whatever its size
  o.matching.filter = MatchFilter::kTextbook;
  o.depth.min_depth = 0.0;
  o.depth.max_depth = std::numeric_limits<double>::max();
  o.depth.round_to_nearest = false;
  o.undistort = false;
  o.weight_by_octave = false;
  o.pnp = PnpMethod::kIterative;
  o.refinement.mode = BundleMode::kTextbook;
  o.refinement.iterations = 100;
  o.depth_path = DepthPath::kOff;  // the textbook has features only
  o.retry_with_sift = false;
  return o;
}

std::string TwoViewOptions::validate() const {
  for (const std::string& p :
       {orb.validate(), matching.validate(), depth.validate(), ransac.validate(),
        refinement.validate(), failure_rule.validate(), registration.validate(),
        rgbd_alignment.validate(), alignment_evidence.validate(), covariance.validate(),
        slide_search.validate(), repeat_search.validate()}) {
    if (!p.empty()) return p;
  }
  if (!(cross_check_below_consistency >= 0 && cross_check_below_consistency <= 1)) {
    return "cross-check consistency must be in [0, 1]";
  }
  if (!(min_registration_fitness >= 0 && min_registration_fitness <= 1)) {
    return "min registration fitness must be in [0, 1]";
  }
  if (!(min_photometric_agreement >= -1 && min_photometric_agreement <= 1)) {
    return "min photometric agreement must be in [-1, 1]";
  }
  if (!(rival_photometric_margin >= 0) || !(clear_consistency_margin >= 0)) {
    return "rival margins must be >= 0";
  }
  if (!(conclusive_consistency >= 0 && conclusive_consistency <= 1) ||
      !(conclusive_photometric_agreement >= -1 && conclusive_photometric_agreement <= 1)) {
    return "conclusive consistency must be in [0, 1], photometric agreement in [-1, 1]";
  }
  if (conclusive_min_explained_pairs < 0) return "conclusive explained pairs must be >= 0";
  if (!(min_overlap >= 0 && min_overlap <= 1)) return "min overlap must be in [0, 1]";
  if (!(min_depth_only_overlap >= 0 && min_depth_only_overlap <= 1)) {
    return "min depth-only overlap must be in [0, 1]";
  }
  if (!(min_depth_only_consistency >= 0 && min_depth_only_consistency <= 1)) {
    return "min depth-only consistency must be in [0, 1]";
  }
  if (!(hopeless_consistency_gap >= 0) || std::isinf(hopeless_consistency_gap)) {
    return "hopeless consistency gap must be finite and >= 0";
  }
  if (!(same_coarse_pose_deg >= 0) || !(same_coarse_pose_m >= 0) ||
      std::isinf(same_coarse_pose_deg) || std::isinf(same_coarse_pose_m)) {
    return "same coarse pose bounds must be finite and >= 0";
  }
  if (!(min_rival_depth_only_overlap >= 0 && min_rival_depth_only_overlap <= 1)) {
    return "min rival depth-only overlap must be in [0, 1]";
  }
  if (aligned_registration_candidates < 0) {
    return "aligned registration candidates must be >= 0";
  }
  if (sift_retry_min_keypoints < 0 || sift_retry_max_contradicted_inliers < 0) {
    return "SIFT retry keypoints and contradicted inliers must be >= 0";
  }
  if (features_judge_pairs < 1 || !(min_explained_fraction >= 0 && min_explained_fraction <= 1)) {
    return "feature judging: pairs must be >= 1 and the explained fraction in [0, 1]";
  }
  if (!(time_budget_ms >= 0) || std::isinf(time_budget_ms)) {
    return "time budget must be finite and >= 0 ms";
  }
  return "";
}

const char* toString(DepthPath path) {
  switch (path) {
    case DepthPath::kAuto:
      return "auto";
    case DepthPath::kOff:
      return "off";
    case DepthPath::kAlways:
      return "always";
  }
  return "?";
}

DepthPath parseDepthPath(const std::string& name) {
  for (DepthPath p : {DepthPath::kAuto, DepthPath::kOff, DepthPath::kAlways}) {
    if (name == toString(p)) return p;
  }
  throw Error("unknown depth path '" + name + "' (auto, off, always)");
}

namespace {

// A given frame's features found with `options`: its own, or those an estimate before this one
// kept for it (the SIFT retry's); none otherwise.
std::optional<Features> knownFeatures(const FrameFeatures* frame, const OrbOptions& options) {
  if (frame == nullptr) return std::nullopt;
  if (frame->options == options) return frame->features;
  if (frame->later) return frame->later->find(options);
  return std::nullopt;
}

// The two images' features: each given frame's where known, the rest detected (both side by
// side when neither is known). What is detected for a given frame is kept in it for its next
// pairs; the same image and options give the same features, so the answer is the same.
void detectFeatures(const cv::Mat& image1, const cv::Mat& image2, const OrbOptions& options,
                    const GivenFeatures& given, FeatureStage* stage) {
  std::optional<Features> known1 = knownFeatures(given.first, options);
  std::optional<Features> known2 = knownFeatures(given.second, options);
  if (known1 && known2) {
    stage->f1 = std::move(*known1), stage->f2 = std::move(*known2);
  } else if (known1) {
    stage->f1 = std::move(*known1), stage->f2 = detectOrb(image2, options);
  } else if (known2) {
    stage->f1 = detectOrb(image1, options), stage->f2 = std::move(*known2);
  } else {
    std::tie(stage->f1, stage->f2) = detectOrbPair(image1, image2, options);
  }
  if (given.first && !known1 && given.first->later) given.first->later->keep(options, stage->f1);
  if (given.second && !known2 && given.second->later) {
    given.second->later->keep(options, stage->f2);
  }
}

// Features, matching and the 3D-2D pairs into r; false when there are no keypoints.
bool detectAndPair(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                   const Camera& camera, const TwoViewOptions& options, FeatureStage* stage,
                   TwoViewResult* r, const GivenFeatures& given = {}) {
  stage->depth_options = options.depth;
  stage->depth_options.depth_scale = camera.depth_scale;
  stage->geometry = camera.pinhole;
  stage->geometry.distortion = {};
  auto t = Clock::now();
  detectFeatures(image1, image2, options.orb, given, stage);
  r->times_ms.features_ms = msSince(t);
  r->counts.keypoints1 = static_cast<int>(stage->f1.keypoints.size());
  r->counts.keypoints2 = static_cast<int>(stage->f2.keypoints.size());
  r->keypoints1 = stage->f1.keypoints;
  r->keypoints2 = stage->f2.keypoints;

  t = Clock::now();
  const std::vector<cv::DMatch> matches =
      matchDescriptors(stage->f1.descriptors, stage->f2.descriptors, options.matching);
  r->times_ms.matching_ms = msSince(t);
  r->counts.matches = static_cast<int>(matches.size());

  t = Clock::now();
  r->pairs = buildCorrespondences(stage->f1, stage->f2, matches, depth1, camera.pinhole,
                                  stage->depth_options, options.undistort);
  r->times_ms.depth_ms = msSince(t);
  r->counts.pairs = static_cast<int>(r->pairs.size());
  if (r->counts.keypoints1 == 0 || r->counts.keypoints2 == 0) {
    r->failure = "no keypoints in image " + std::string(r->counts.keypoints1 == 0 ? "1" : "2");
    return false;
  }
  return true;
}

}  // namespace

double consistencyOf(const SE3Quat& T, const cv::Mat& depth1, const cv::Mat& depth2,
                     const Camera& camera) {
  if (depth2.empty()) return -1;
  return measureDepthConsistency(depth1, depth2, T, camera.pinhole, camera.depth_scale)
      .consistency();
}

namespace {

// The feature path: PnP RANSAC and BA, judged by the failure rule. r->ok when accepted.
void featurePath(const cv::Mat& depth1, const cv::Mat& depth2, const Camera& camera,
                 const TwoViewOptions& options, FeatureStage* stage, TwoViewResult* r) {
  const auto t = Clock::now();
  stage->pnp = estimatePnp(r->pairs, stage->geometry, options.pnp, options.ransac);
  r->times_ms.pnp_ms = msSince(t);
  if (!stage->pnp.ok) {
    r->failure = stage->pnp.failure;
    return;
  }
  r->T_init = stage->pnp.T_21;
  r->counts.inliers = stage->pnp.num_inliers;
  r->counts.competitor_inliers = stage->pnp.competitor_inliers;
  // The refined pose's evidence, measured beside its covariance.
  auto measureAtRefinedPose = [&] {
    r->inlier_coverage = inlierCoverage(r->pairs, r->inlier);
    const auto consistency_start = Clock::now();
    r->depth_consistency = consistencyOf(r->T_21, depth1, depth2, camera);
    if (!depth2.empty()) r->times_ms.depth_consistency_ms += msSince(consistency_start);
  };
  if (!refineInto(*stage, stage->pnp.inlier, stage->pnp.T_21, depth2, options, r,
                  measureAtRefinedPose)) {
    return;
  }
  stage->solved = true;
  PoseEvidence evidence;
  evidence.pairs = r->counts.pairs;
  evidence.inliers = r->counts.inliers;
  evidence.chi2_final = r->chi2_final;
  evidence.competitor_inliers = r->counts.competitor_inliers;
  evidence.inlier_coverage = r->inlier_coverage;
  evidence.depth_consistency = r->depth_consistency;
  evidence.covariance_ok = r->covariance_ok;
  evidence.covariance = r->judged_covariance;
  const FailureVerdict verdict = options.failure_rule.check(evidence);
  if (verdict.refused()) {
    r->failure_rule = verdict.rule;
    r->failure = verdict.message;
    return;
  }
  r->ok = true;
  r->path = "features";
}

}  // namespace

// sqrt of the trace of the nominal covariance's rotation (deg) and translation (cm) blocks;
// infinite without one.
std::pair<double, double> nominalSigmas(const TwoViewResult& r) {
  if (!r.covariance_ok) return {INFINITY, INFINITY};
  const PoseSigmas s = poseSigmas(r.nominal_covariance);
  return {s.deg, s.cm};
}

namespace {

// Runs the feature path again with `retry` after the first front end gave no pose, and keeps its
// result when it has a pose, or a refined pose the first lacked or one with more inliers than
// the first's refused one: the depth path starts from it, and a seed it finds conclusive spares
// the global registration (the rendered rich room at 60 degrees and 0.5 m: ORB's refused pose
// held 28 of 79 pairs, too few for its alignment to be conclusive; SIFT's, refused for its
// inliers' small area, 73 of 123).
bool retryFeatures(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                   const cv::Mat& depth2, const Camera& camera, const TwoViewOptions& retry,
                   const GivenFeatures& given, FeatureStage* stage, TwoViewResult* r) {
  TwoViewResult s;
  FeatureStage retry_stage;
  if (detectAndPair(image1, depth1, image2, camera, retry, &retry_stage, &s, given)) {
    featurePath(depth1, depth2, camera, retry, &retry_stage, &s);
  }
  const bool better_seed =
      retry_stage.solved && (!stage->solved || s.counts.inliers > r->counts.inliers);
  if (!s.ok && !better_seed) return false;
  s.detector = toString(retry.orb.detector);
  *r = std::move(s), *stage = std::move(retry_stage);
  return true;
}

// The cheap evidence: a feature pose the rule refused, aligned by the depth path alone and
// conclusive there, settles the pair before the SIFT retry and the global registration run.
// True (with *r the answer) when it does.
bool settledByAlignment(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                        const cv::Mat& depth2, const Camera& camera, const TwoViewOptions& options,
                        const FeatureStage& stage, TimeBudget* budget, DepthCandidateCache* aligned,
                        TwoViewResult* r) {
  if (r->ok || !stage.solved || !wantsDepthPath(*r, depth2, options)) return false;
  TwoViewResult d = depthPath(image1, depth1, image2, depth2, camera, options, *r, stage,
                              /*conclusive_only=*/true, budget, /*depth1_kept=*/nullptr, aligned);
  if (d.ok) {
    *r = std::move(d);
    return true;
  }
  r->times_ms.alignment_ms = d.times_ms.alignment_ms;
  return false;
}

// The SIFT retry where wantsSiftRetry says so; returns the options the kept features were
// found with (the depth path refines with their weights).
TwoViewOptions siftRetryStage(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                              const cv::Mat& depth2, const Camera& camera,
                              const TwoViewOptions& options, const GivenFeatures& given,
                              TimeBudget* budget, FeatureStage* stage, TwoViewResult* r) {
  if (budget->cut() || !wantsSiftRetry(*r, image1.size(), options)) return options;
  if (!budget->allows(BudgetedStage::kSiftRetry)) return options;
  const auto start = Clock::now();
  StageTimes times = r->times_ms;  // the first pass's stages; the retry is timed whole
  const TwoViewOptions sift = siftRetryOptions(options, image1.size());
  const bool kept = retryFeatures(image1, depth1, image2, depth2, camera, sift, given, stage, r);
  times.sift_retry_ms = msSince(start);
  budget->record(BudgetedStage::kSiftRetry, times.sift_retry_ms);
  r->times_ms = times;
  return kept ? sift : options;
}

// The depth path in full where wantsDepthPath says so, and which pose wins (preferDepthPose).
// A given frame 1 keeps its depth's description for its next registrations (a key frame's).
void depthPathStage(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                    const cv::Mat& depth2, const Camera& camera, const TwoViewOptions& options,
                    const FeatureStage& stage, const GivenFeatures& given, TimeBudget* budget,
                    DepthCandidateCache* aligned, TwoViewResult* r) {
  if (budget->cut()) return;
  if (!wantsDepthPath(*r, depth2, options)) {
    if (!r->ok && depth2.empty() && options.depth_path != DepthPath::kOff) {
      r->failure += " (no depth 2: the depth-only path could not run)";
    }
    return;
  }
  std::optional<PoseEstimate> dense;  // the depths' and colours' own estimate of d's pose
  LaterFeatures* depth1_kept = given.first != nullptr ? given.first->later.get() : nullptr;
  TwoViewResult d = depthPath(image1, depth1, image2, depth2, camera, options, *r, stage,
                              /*conclusive_only=*/false, budget, depth1_kept, aligned, &dense);
  const bool agree = r->ok && d.ok && !posesDiffer(r->T_21, d.T_21);
  const bool depth_wins = d.ok && (!r->ok || preferDepthPose(*r, d, agree, options));
  if (depth_wins) {
    std::swap(*r, d);  // d now holds the feature path's result
  } else {
    r->times_ms.registration_ms = d.times_ms.registration_ms;
    r->times_ms.plugin_load_ms = d.times_ms.plugin_load_ms;
    r->times_ms.alignment_ms = d.times_ms.alignment_ms;
    r->registration_fitness = d.registration_fitness;
    r->counts.depth_candidates = d.counts.depth_candidates;
    r->counts.depth_duplicates = d.counts.depth_duplicates;
  }
  if (agree) {
    r->path = "both";
    const TwoViewResult& features = depth_wins ? d : *r;
    fuseAgreeingPoses(features, dense, depth1, depth2, camera, options, r);
  }
  if (!r->ok && !d.ok) {
    r->failure = "features: " + r->failure + "; depth path: " + d.failure;
    r->failure_rule = d.failure_rule;
  }
}

// A pair the time budget cut short is refused, whatever the stages before the cut had: the
// evidence of the stage that did not run was never weighed (time_budget.h).
void refuseForBudget(const TimeBudget& budget, TwoViewResult* r) {
  std::string before = r->ok ? std::string() : r->failure;
  // A depth path the budget cut refused with the cut itself: said once, in front.
  const std::string repeated = "; depth path: " + budget.cutMessage();
  if (const size_t at = before.find(repeated); at != std::string::npos) {
    before.erase(at, repeated.size());
  }
  r->ok = false;
  r->failure_rule = "time_budget";
  r->failure = budget.cutMessage() + (before.empty() ? "" : " (before it: " + before + ")");
}

void checkCall(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
               const cv::Mat& depth2, const Camera& camera, const TwoViewOptions& options,
               const GivenFeatures& given) {
  std::string problem = options.validate();
  if (problem.empty()) problem = camera.validate();
  if (!problem.empty()) throw Error(problem);
  checkTwoViewInputs(image1, depth1, image2, depth2);
  checkCameraSize(image1, camera);
  if (given.first) checkFrameFeatures(*given.first, image1, options.orb, "image 1");
  if (given.second) checkFrameFeatures(*given.second, image2, options.orb, "image 2");
}

}  // namespace

// The stages in order, cheap evidence first; each decision is in two_view_decisions.cpp.
TwoViewResult estimateTwoView(const cv::Mat& image1, const cv::Mat& given_depth1,
                              const cv::Mat& image2, const cv::Mat& given_depth2,
                              const Camera& camera, const TwoViewOptions& options,
                              const FrameFeatures* features1, const FrameFeatures* features2) {
  const auto start = Clock::now();
  retainFreedHeapMemoryOnce();  // the next pair reuses this one's pages (heap_retention.h)
  const GivenFeatures given{features1, features2};
  checkCall(image1, given_depth1, image2, given_depth2, camera, options, given);
  // Holes marked 65535 read as holes everywhere below (the registration, the consistency and
  // the alignment read raw depth values), not as surfaces 13-65 m away.
  const cv::Mat depth1 = withoutSaturatedDepth(given_depth1);
  const cv::Mat depth2 = withoutSaturatedDepth(given_depth2);
  TimeBudget budget(start, options.time_budget_ms);
  TwoViewResult r;
  FeatureStage stage;
  if (detectAndPair(image1, depth1, image2, camera, options, &stage, &r, given)) {
    featurePath(depth1, depth2, camera, options, &stage, &r);
  }
  r.detector = toString(options.orb.detector);
  DepthCandidateCache aligned;
  if (!settledByAlignment(image1, depth1, image2, depth2, camera, options, stage, &budget, &aligned,
                          &r)) {
    const TwoViewOptions used =
        siftRetryStage(image1, depth1, image2, depth2, camera, options, given, &budget, &stage, &r);
    depthPathStage(image1, depth1, image2, depth2, camera, used, stage, given, &budget, &aligned,
                   &r);
  }
  if (budget.cut()) refuseForBudget(budget, &r);
  if (!r.ok) r.path.clear();
  r.times_ms.total_ms = msSince(start);
  return r;
}

}  // namespace pnpba
