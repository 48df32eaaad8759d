// The depth path of the two-view pose: candidates, their RGB-D alignment, and the evidence
// that decides between them (two_view_stages.h).
//
//   images      the pair's own, or scaled to 640 x 480's pixel count where larger
//               (DepthPathView); the feature pairs keep their full-resolution pixels;
//   candidates  the feature pose when one was solved (accepted or refused), first; the global
//               depth registration's pose (FPFH, RANSAC, ICP) only when that one is not
//               conclusive (consistency >= 0.98, colour >= 0.9, half the feature pairs
//               explained, or 20 with no rival RANSAC pose; or an accepted feature pose its
//               alignment supports and agrees with);
//   alignment   each refined by the direct RGB-D alignment (rgbd_alignment.h): colour fixes
//               what depth alone leaves sliding, the feature pairs join the same refinement;
//               a candidate the depths contradict at half resolution stops there
//               (hopeless: never returned, its evidence not measured), and so does one whose
//               coarse levels end where an earlier candidate's did (that candidate again);
//   slide       a candidate the depths support below conclusive_consistency is stepped
//               along camera 2's axes, aligned again from a shift the depths support better,
//               and replaced when the depths support the result better (slide_search.h);
//   repeat      the best-supported candidate, where the depths alone carry it, is shifted
//               along camera 1's axes and the direction its covariance is loosest along by
//               0.3-2 m: a twin one period along a repeat that the depths support nearly as
//               well, or the far end (0.6 m) of a slide they leave free, joins the candidates
//               (repeat_search.h);
//   evidence    per candidate: depth consistency of both depth images, photometric agreement,
//               overlap and information (alignment_evidence.h), the feature pairs it explains
//               (alignment, slide and evidence: CandidateAligner, depth_candidates.h);
//   decision    the best-supported candidate (consistency, then colour, then feature pairs,
//               each when clearly different), refused by the rules tabled in
//               depth_path_judging.h (depth_inconsistent, rival_alignment, features_disagree,
//               photometric, degenerate, registration_overlap);
//   result      the chosen pose with the alignment's covariance and the calibration's; the
//               feature BA on the pairs it explains where that is near and more precise.
#include <Eigen/Eigenvalues>
#include <cstdio>
#include <functional>
#include <optional>

#include "depth_candidates.h"
#include "depth_path_judging.h"
#include "open3d_plugin_api.h"
#include "pnpba/core/plugin.h"
#include "pnpba/pipeline/covariance_model.h"
#include "pnpba/pipeline/depth_consistency.h"
#include "pnpba/pipeline/depth_registration.h"
#include "pnpba/pipeline/repeat_search.h"
#include "pnpba/pipeline/slide_search.h"
#include "registration/registration.h"
#include "registration_work.h"
#include "rgbd_residuals.h"
#include "time_budget.h"
#include "two_view_stages.h"

namespace pnpba {

namespace {

// The direction in camera 1 the candidate's translation is loosest along, by its evidence's
// covariance (none where it has none): a slide the scene leaves free need not lie along camera
// 1's axes. The covariance is of a left translation, in camera 2; the repeat search shifts
// camera 1's scene, d = R^T v.
std::vector<Eigen::Vector3d> loosestDirection(const DepthCandidate& c) {
  if (!c.evidence.covariance_ok) return {};
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(
      c.evidence.covariance.bottomRightCorner<3, 3>());
  if (eigen.info() != Eigen::Success) return {};
  return {c.T.rotation().toRotationMatrix().transpose() * eigen.eigenvectors().col(2)};
}

// A candidate's alignment, its time recorded as the budget's expectation of the next one (unless
// the deadline stopped it: a lower bound of its time, not its time).
template <typename Align>
DepthCandidate alignWithin(TimeBudget* budget, Align align) {
  const auto start = Clock::now();
  DepthCandidate c = align();
  if (!c.out_of_time) budget->record(BudgetedStage::kCandidateAlignment, msSince(start));
  return c;
}

// The registration may offer only one of a repeat's twins, so none shows as a rival: where the
// depths alone carry the best-supported candidate, a twin the depths support nearly as well one
// period along a repeat (or the far end of a slide they leave free) is aligned as one more
// candidate (repeat_search.h), for the evidence to separate from it or to refuse the pair as
// rival_alignment.
void addRepeatTwins(const DepthPathView& view, const TwoViewOptions& options,
                    CandidateAligner* aligner, TimeBudget* budget,
                    std::vector<DepthCandidate>* candidates, TwoViewResult* r) {
  if (candidates->empty() || !(options.repeat_search.max_shift_m > 0)) return;
  const DepthCandidate& leading = (*candidates)[bestCandidate(*candidates, options)];
  if (leading.hopeless || featureSupported(leading, options) || !supported(leading, options)) {
    return;
  }
  // A twin unsought could be the rival that refuses the pair: past the deadline the search
  // cuts it.
  if (budget->ranOutDuring(BudgetedStage::kCandidateAlignment)) return;
  const auto start = Clock::now();
  const std::vector<RepeatTwin> twins = findRepeatTwins(
      leading.T,
      [&](const SE3Quat& T) {
        return measureDepthConsistency(view.depth1, view.depth2, T, view.camera.pinhole,
                                       view.camera.depth_scale, options.repeat_search.stride);
      },
      options.repeat_search, loosestDirection(leading));
  r->times_ms.alignment_ms += msSince(start);
  for (const RepeatTwin& twin : twins) {
    // A twin left unaligned could be the rival that refuses the pair: the cut refuses it.
    if (!budget->allows(BudgetedStage::kCandidateAlignment)) return;
    DepthCandidate c = alignWithin(
        budget, [&] { return aligner->evaluate("repeat twin", twin.T, -1.0, {}, *candidates); });
    if (c.out_of_time) {
      budget->ranOutDuring(BudgetedStage::kCandidateAlignment);
      return;
    }
    if (c.duplicate) {
      ++r->counts.depth_duplicates;
      continue;
    }
    c.rank = 1;  // one more pose tried: a rival's overlap bar if it is chosen
    c.repeat_twin = true;
    c.free_slide = twin.free_slide;
    candidates->push_back(std::move(c));
  }
}

}  // namespace

TwoViewResult depthPath(const cv::Mat& image1_full, const cv::Mat& depth1_full,
                        const cv::Mat& image2_full, const cv::Mat& depth2_full,
                        const Camera& camera_full, const TwoViewOptions& options,
                        const TwoViewResult& features, const FeatureStage& stage,
                        bool conclusive_only, TimeBudget* budget, LaterFeatures* depth1_kept,
                        DepthCandidateCache* cache, std::optional<PoseEstimate>* dense) {
  if (dense != nullptr) dense->reset();
  TwoViewResult r = features;  // keeps keypoints, pairs, counts and stage times
  r.ok = false;
  r.failure.clear();
  r.failure_rule.clear();
  r.path.clear();
  // The budget cut the pair short: the driver refuses it (time_budget.h).
  auto cutShort = [&r, budget] {
    r.failure = budget->cutMessage();
    return r;
  };

  // One image pyramid for every candidate's alignment and evidence, of the working images (at
  // most about kWorkingPixels pixels); its time, and the evidence's, count as the alignment's. The
  // feature pairs keep their full-resolution pixels and camera.
  const auto view_start = Clock::now();
  std::optional<DepthPathView> own_view;
  std::optional<DepthPathView>& view_slot = cache != nullptr ? cache->view : own_view;
  if (!view_slot) {
    view_slot = depthPathView(image1_full, depth1_full, image2_full, depth2_full, camera_full);
  }
  const DepthPathView& view = *view_slot;
  std::optional<RecycledPyramid> own_pyramid;
  RecycledPyramid& recycled = cache != nullptr ? cache->pyramid : own_pyramid.emplace();
  if (!recycled.built) {
    rgbdPyramidInto(view.image1, view.depth1, view.image2, view.depth2, view.camera.pinhole,
                    view.camera.depth_scale, std::max(1, options.rgbd_alignment.levels),
                    &recycled.levels);
    recycled.built = true;
    r.times_ms.alignment_ms += msSince(view_start);
  }
  CandidateAligner aligner(view, &recycled, camera_full.pinhole, r.pairs, stage, options,
                           &r.times_ms.alignment_ms, budget);
  const FailureRule& rule_options = options.failure_rule;
  // Every candidate aligned (hopeless ones too), the feature pose's first.
  std::vector<DepthCandidate> candidates;

  // Cheap evidence first: the feature pose, aligned, is kept without a global registration when
  // the depths, the colours and the feature pairs all support it clearly, or when the feature
  // path accepted it and the aligned pose, supported by the depths, does not contradict it.
  if (stage.solved) {
    // The same feature pose on the same pairs was aligned before (the conclusive-only pass).
    const bool cached =
        cache != nullptr && cache->valid && cache->pairs == r.pairs.size() &&
        cache->candidate.T_seed.to_homogeneous_matrix() == features.T_21.to_homogeneous_matrix();
    // An accepted, precise feature pose stands whenever its alignment agrees with it
    // (preferDepthPose): aligned at quarter (else down to half) resolution, agreeing and
    // supported by the depths, it settles the pair; anything else is aligned at full resolution.
    const auto [f_deg, f_cm] = nominalSigmas(features);
    const bool stands_if_confirmed = features.ok && f_deg <= options.cross_check_sigma_deg &&
                                     f_cm <= options.cross_check_sigma_cm;
    auto confirms = [&](const DepthCandidate& c) {
      return supported(c, options) && !posesDiffer(c.T, features.T_21);
    };
    const BudgetedStage seed_stage =
        stands_if_confirmed ? BudgetedStage::kFeatureCheck : BudgetedStage::kSeedAlignment;
    if (!cached && !budget->allows(seed_stage)) return cutShort();
    const auto seed_start = Clock::now();
    candidates.push_back(
        cached ? cache->candidate
               : aligner.evaluate(
                     "features", features.T_21, -1.0,
                     stands_if_confirmed ? confirms : std::function<bool(const DepthCandidate&)>(),
                     candidates));
    if (candidates.back().out_of_time) {
      budget->ranOutDuring(seed_stage);
      return cutShort();
    }
    if (!cached) budget->record(seed_stage, msSince(seed_start));
    // The confirmed feature pose stands as it is (preferDepthPose keeps it): the aligned pose is
    // returned for the agreement alone, without the evidence, covariance and BA that only a
    // depth-path answer needs (they cost 4-5 ms at 640 x 480 and changed no answer).
    if (candidates[0].confirms_features) {
      r.counts.depth_candidates = 1;
      r.ok = true;
      r.path = "depth";
      r.T_21 = candidates[0].T;
      r.depth_consistency = candidates[0].consistency;
      return r;
    }
    if (cache != nullptr) {
      cache->valid = true;
      cache->pairs = r.pairs.size();
      cache->candidate = candidates.back();
    }
  }
  // The feature pairs do not argue against a candidate that explains half of them, or enough of
  // them where no rival RANSAC pose has comparable support: the rest are then wrong matches
  // that agree on nothing (TwoViewOptions::conclusive_min_explained_pairs).
  auto pairsAgree = [&](const DepthCandidate& c) {
    if (c.explained >=
        std::max(options.ransac.min_inliers, static_cast<int>(r.pairs.size() + 1) / 2)) {
      return true;
    }
    return options.conclusive_min_explained_pairs > 0 &&
           c.explained >= options.conclusive_min_explained_pairs &&
           stage.pnp.competitor_inliers <= rule_options.max_competitor_ratio * c.explained;
  };
  const bool conclusive =
      !candidates.empty() &&
      ((candidates[0].consistency >= options.conclusive_consistency &&
        photometric(candidates[0]) >= options.conclusive_photometric_agreement &&
        pairsAgree(candidates[0])) ||
       (features.ok && supported(candidates[0], options) &&
        !posesDiffer(candidates[0].T, features.T_21)));
  if (conclusive_only && !conclusive) {
    r.failure = "the feature pose alone is not conclusive";
    return r;
  }
  if (!conclusive) {
    // Its time grows with its clouds: expected per thousand points it is predicted to keep. It
    // answers nothing without one candidate's alignment after it, so that must fit too (a
    // registration that would be cut off there is time spent on a refusal).
    const double kilopoints = budget->active() ? predictedRegistrationKilopoints(
                                                     view.depth1, view.depth2, view.camera.pinhole,
                                                     view.camera.depth_scale, options.registration)
                                               : 1;
    if (!budget->allows(BudgetedStage::kRegistration, kilopoints,
                        TimeBudget::expectedMs(BudgetedStage::kCandidateAlignment))) {
      return cutShort();
    }
    DepthRegistrationOptions registration = options.registration;
    registration.covariance = false;  // the alignment's evidence gives the pose's covariance
    // A process's first registration that takes one of Open3D's steps opens its plugin before it
    // can start (time_budget.h); the default steps open none.
    if (budget->active() && registrationNeedsOpen3d(registration) && !pluginLoaded(kOpen3dPlugin) &&
        !budget->allows(BudgetedStage::kPluginOpening, 1,
                        TimeBudget::expectedMs(BudgetedStage::kRegistration) * kilopoints +
                            TimeBudget::expectedMs(BudgetedStage::kCandidateAlignment))) {
      return cutShort();
    }
    // Timed here, not by the plugin, less the plugin's opening in a process's first
    // registration (Open3D, tens of ms), which is a stage of its own.
    const auto registration_start = Clock::now();
    const DepthRegistration reg =
        registerDepthImages(view.depth1, view.depth2, view.camera.pinhole, view.camera.depth_scale,
                            registration, depth1_kept);
    r.times_ms.plugin_load_ms = reg.plugin_load_ms;
    r.times_ms.registration_ms = msSince(registration_start) - reg.plugin_load_ms;
    // A registration that took depth 1's description from an earlier one did half the work:
    // not what the budget expects of the next.
    if (!reg.depth1_described_before) {
      budget->record(BudgetedStage::kRegistration, r.times_ms.registration_ms, kilopoints);
    }
    if (reg.plugin_load_ms > 0) budget->record(BudgetedStage::kPluginOpening, reg.plugin_load_ms);
    if (reg.ok) {
      // Every distinct pose the registration found support for that the screening keeps is
      // aligned and judged: a rival the evidence cannot separate from the chosen pose refuses
      // the pair (rival_alignment).
      bool first = true;
      const std::vector<size_t> screened = aligner.screened(reg.candidates);
      if (budget->ranOutDuring(BudgetedStage::kCandidateAlignment)) return cutShort();
      for (size_t k : screened) {
        if (!budget->allows(BudgetedStage::kCandidateAlignment)) return cutShort();
        DepthCandidate c = alignWithin(budget, [&] {
          return aligner.evaluate(first ? "registration" : "registration rival",
                                  reg.candidates[k].T_21, reg.candidates[k].fitness, {},
                                  candidates);
        });
        if (c.out_of_time) {
          budget->ranOutDuring(BudgetedStage::kCandidateAlignment);
          return cutShort();
        }
        first = false;
        if (c.duplicate) {
          ++r.counts.depth_duplicates;
          continue;
        }
        c.rank = static_cast<int>(k);
        candidates.push_back(std::move(c));
      }
    } else if (candidates.empty()) {
      r.registration_fitness = reg.fitness;
      r.failure = reg.failure;
      return r;
    }
  }

  addRepeatTwins(view, options, &aligner, budget, &candidates, &r);
  if (budget->cut()) return cutShort();
  r.counts.depth_candidates = static_cast<int>(candidates.size());
  // Which candidate the evidence supports (depth_path_judging.h).
  const size_t best = bestCandidate(candidates, options);
  const DepthCandidate& chosen = candidates[best];
  if (chosen.hopeless) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "the depths contradict every candidate: the best, the %s pose, has consistency "
                  "%.2f",
                  chosen.seed.c_str(), chosen.consistency);
    r.failure_rule = "depth_inconsistent";
    r.failure = text;
    return r;
  }
  r.T_init = chosen.T_seed;
  r.T_21 = chosen.T;
  // The alignment's information already carries its measured residual scales; the model adds
  // the calibration's uncertainty through the alignment's own samples and weights.
  r.nominal_covariance = chosen.evidence.covariance;
  r.covariance_ok = chosen.evidence.covariance_ok;
  r.variance_factor = 1;
  r.depth_variance_factor = 1;
  r.calibration_sensitivity = chosen.evidence.calibration_sensitivity;
  r.judged_covariance =
      r.nominal_covariance + calibrationCovariance(r.calibration_sensitivity, chosen.T,
                                                   options.covariance, CalibrationMetric::kDense);
  r.covariance = r.judged_covariance + motionCovariance(chosen.T, options.covariance);
  std::optional<PoseEstimate> dense_estimate;
  if (chosen.evidence.dense_ok) {
    PoseEstimate& e = dense_estimate.emplace();
    e.T_21 = SE3Quat::exp(chosen.evidence.dense_step) * chosen.T;
    e.own = e.judged = e.nominal = chosen.evidence.dense_covariance;
    e.calibration_sensitivity = chosen.evidence.dense_calibration_sensitivity;
  }
  r.chi2_initial = r.chi2_final = 0;
  r.ba_iterations = 0;
  r.solver = options.align_rgbd ? "rgbd-alignment" : "registration";
  r.counts.inliers = 0;
  r.counts.competitor_inliers = 0;
  r.inlier.assign(r.pairs.size(), 0);
  r.photometric_agreement = photometric(chosen);
  r.overlap = chosen.evidence.overlap();

  // The feature pairs the pose explains, refined by the BA: kept when it stays near the
  // aligned pose and is the more precise (many well-spread features beat the depths; a few far
  // or coplanar ones do not).
  std::vector<char> explained;
  bool depth_pose_stands = true;
  if (aligner.explainedPairs(chosen.T, &explained) >= options.failure_rule.min_inliers) {
    TwoViewResult refined = r;
    if (refineInto(stage, explained, chosen.T, depth2_full, options, &refined) &&
        !posesDiffer(refined.T_21, chosen.T) &&
        nominalSigmas(refined).second < nominalSigmas(r).second) {
      r = refined;
      depth_pose_stands = false;
    }
  }
  // What the alignment's information cannot see: how loosely the depths pin a slide, in the
  // covariance of the depth path's own pose where it stands (the one the failure rule judges as
  // well). Not in the dense estimate a `both` pose fuses: there the feature pairs pin the slide,
  // and the floor on the dense part held the fused translation to the feature BA's alone while
  // the fused pose was the better one (covariance_bench, the poor room's `both` poses: mean NEES
  // 3.4 with it, 4.2-4.4 without; their errors against the fused estimates' own covariances,
  // the calibration's share taken out: 1.5 / 1.8 with it, 2.9 / 2.8 without, of 3 each).
  if (depth_pose_stands) {
    const auto start = Clock::now();
    const Eigen::Vector3d slide = slideSigmas(
        chosen.T, chosen.consistency, [&](const SE3Quat& T) { return aligner.consistencyAt(T); },
        options.covariance.slide_probe_m, options.covariance.slide_consistency_sigma);
    const Eigen::Vector3d above = slideVarianceAbove(slide, r.nominal_covariance);
    r.judged_covariance.bottomRightCorner<3, 3>().diagonal() += above;
    r.covariance.bottomRightCorner<3, 3>().diagonal() += above;
    r.slide_sigma_m = slide;
    r.times_ms.alignment_ms += msSince(start);
  }
  r.depth_consistency = aligner.consistencyAt(r.T_21);
  r.registration_fitness = chosen.fitness;

  const FailureVerdict verdict = judgeDepthPose(candidates, best, r, options);
  if (verdict.refused()) {
    r.failure_rule = verdict.rule;
    r.failure = verdict.message;
    return r;
  }
  r.ok = true;
  r.path = "depth-registration";
  if (dense != nullptr) *dense = dense_estimate;
  return r;
}

bool depthPathOpensOpen3d(const TwoViewOptions& options) {
  DepthRegistrationOptions registration = options.registration;
  registration.covariance = false;  // as the depth path runs it
  return options.depth_path != DepthPath::kOff && registrationNeedsOpen3d(registration);
}

}  // namespace pnpba
