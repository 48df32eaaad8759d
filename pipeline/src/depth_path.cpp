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
//   evidence    per candidate: depth consistency of both depth images, photometric agreement,
//               overlap and information (alignment_evidence.h), the feature pairs it explains;
//   decision    the best-supported candidate (consistency, then colour, then feature pairs,
//               each when clearly different), refused when
//                 depth_inconsistent    the depths contradict it (< 0.9), or carry it alone
//                                       (< 20 feature pairs) below 0.95
//                 rival_alignment       another candidate differs and the evidence does not
//                                       separate the two
//                 features_disagree     it explains < 5 % of 20 or more feature pairs
//                 photometric           its aligned images correlate below 0.7
//                 degenerate            the information leaves a direction free
//                 registration_overlap  the registration or the pose covers too little: a
//                                       pose the depths alone carry needs a quarter of
//                                       frame 1 (a slide or flip of a few planes fits as
//                                       well as the truth over a sliver)
#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numeric>
#include <optional>

#include "pnpba/pipeline/alignment_evidence.h"
#include "pnpba/pipeline/covariance_model.h"
#include "pnpba/pipeline/depth_registration.h"
#include "pnpba/pipeline/rgbd_alignment.h"
#include "rgbd_residuals.h"
#include "two_view_stages.h"

namespace pnpba {

namespace {

using Candidate = DepthCandidate;

double photometric(const Candidate& c) { return c.evidence.photometric_agreement; }

int explainedPairs(const Correspondences& pairs, const SE3Quat& T, const PinholeCamera& geometry,
                   double gate_px, std::vector<char>* explained) {
  explained->assign(pairs.size(), 0);
  int n = 0;
  const std::vector<double> e2 = reprojectionErrors2(pairs, T, geometry);
  for (size_t i = 0; i < e2.size(); ++i) n += (*explained)[i] = e2[i] < gate_px * gate_px;
  return n;
}

// Whether two poses the alignment's coarse levels ended at lie within the given bounds
// (TwoViewOptions::same_coarse_pose_deg, same_coarse_pose_m), measured as posesDiffer measures.
bool sameCoarsePose(const SE3Quat& a, const SE3Quat& b, double max_deg, double max_m) {
  const double angle = Eigen::AngleAxisd(a.rotation() * b.rotation().inverse()).angle();
  return angle < max_deg * M_PI / 180.0 && (a.translation() - b.translation()).norm() < max_m;
}

}  // namespace

TwoViewResult depthPath(const cv::Mat& image1_full, const cv::Mat& depth1_full,
                        const cv::Mat& image2_full, const cv::Mat& depth2_full,
                        const Camera& camera_full, const TwoViewOptions& options,
                        const TwoViewResult& features, const FeatureStage& stage,
                        bool conclusive_only, DepthCandidateCache* cache,
                        std::optional<PoseEstimate>* dense) {
  if (dense != nullptr) dense->reset();
  TwoViewResult r = features;  // keeps keypoints, pairs, counts and stage times
  r.ok = false;
  r.failure.clear();
  r.failure_rule.clear();
  r.path.clear();

  const double gate = 4.0 * options.ransac.threshold_px;
  std::vector<AlignmentFeature> features_for_alignment;
  for (const Correspondence& c : r.pairs) {
    features_for_alignment.push_back(
        {c.X_1, c.uv_2,
         options.weight_by_octave ? keypointSigma(stage.f2.keypoints[c.keypoint_2], options.orb)
                                  : 1.0});
  }
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
  const cv::Mat &image1 = view.image1, &depth1 = view.depth1;
  const cv::Mat &image2 = view.image2, &depth2 = view.depth2;
  const Camera& camera = view.camera;
  std::optional<RecycledPyramid> own_pyramid;
  RecycledPyramid& recycled = cache != nullptr ? cache->pyramid : own_pyramid.emplace();
  if (!recycled.built) {
    rgbdPyramidInto(image1, depth1, image2, depth2, camera.pinhole, camera.depth_scale,
                    std::max(1, options.rgbd_alignment.levels), &recycled.levels);
    recycled.built = true;
    r.times_ms.alignment_ms += msSince(view_start);
  }
  const std::vector<RgbdLevel>& pyramid = recycled.levels;
  // A candidate's evidence at its pose: what the depths and the feature pairs say (cheap),
  // then the alignment's own (photometric agreement, overlap, information).
  auto measureSupport = [&](Candidate* c) {
    const auto start = Clock::now();
    c->consistency = consistencyOf(c->T, depth1, depth2, camera);
    std::vector<char> unused;
    c->explained = explainedPairs(r.pairs, c->T, stage.geometry, gate, &unused);
    r.times_ms.alignment_ms += msSince(start);
  };
  // Level 0's gradients, the first time an alignment or evidence works at full resolution.
  auto prepareLevel0 = [&] {
    const auto start = Clock::now();
    prepareFullResolution(&recycled.levels);
    r.times_ms.alignment_ms += msSince(start);
  };
  auto measureEvidence = [&](Candidate* c) {
    prepareLevel0();
    const auto start = Clock::now();
    c->evidence = measureAlignmentAt(pyramid[0], camera_full.pinhole, c->T, features_for_alignment,
                                     options.alignment_evidence);
    r.times_ms.alignment_ms += msSince(start);
  };
  const FailureRule& rule_options = options.failure_rule;
  auto featureSupported = [&](const Candidate& c) {
    return c.explained >= rule_options.min_inliers;
  };
  auto supported = [&](const Candidate& c) {
    return c.consistency >= (featureSupported(c) ? rule_options.min_registration_consistency
                                                 : options.min_depth_only_consistency);
  };
  // A supported but not conclusive candidate may rest along a plain wall, where the alignment
  // cannot see a slide (slide_search.h): a shift the depths support better is aligned again,
  // and the new pose replaces it when the depths support that better by the same margin. Only
  // a pose the depths already support is searched, so no refusal becomes an answer by it.
  auto slide = [&](Candidate* c) {
    if (!options.align_rgbd || !(options.slide_search.step_m > 0) || !supported(*c) ||
        c->consistency >= options.conclusive_consistency) {
      return;
    }
    const auto start = Clock::now();
    const SlideSeed seed = findSlideSeed(
        c->T, c->consistency,
        [&](const SE3Quat& T) { return consistencyOf(T, depth1, depth2, camera); },
        options.slide_search);
    r.times_ms.alignment_ms += msSince(start);
    if (!seed.found) return;
    // Aligned again from the seed down to half resolution first: a seed the alignment pulls
    // back (on the rendered sweep and the real cabinet frames, every one found with the exact
    // calibration) stops there, at a quarter of the full alignment's cost; one that holds more
    // than the candidate's consistency goes on to full resolution, which together is the one
    // alignment over every level.
    prepareLevel0();
    RgbdAlignmentOptions o = options.rgbd_alignment;
    if (o.levels > 1) o.finest_level = 1;
    RgbdAlignment a =
        alignRgbdPyramid(pyramid, camera_full.pinhole, seed.T, features_for_alignment, o);
    r.times_ms.alignment_ms += a.time_ms;
    if (!a.ok) return;
    Candidate moved = *c;
    if (o.finest_level > 0) {
      moved.T = a.T_21;
      measureSupport(&moved);
      if (!(moved.consistency > c->consistency)) return;
      o.finest_level = 0;
      o.levels = 1;
      a = alignRgbdPyramid(pyramid, camera_full.pinhole, a.T_21, features_for_alignment, o);
      r.times_ms.alignment_ms += a.time_ms;
      if (!a.ok) return;
    }
    moved.T = a.T_21;
    measureSupport(&moved);
    if (supported(moved) && moved.consistency >= c->consistency + options.slide_search.min_gain) {
      *c = moved;
    }
  };
  // `settled_coarse(c)` (given c's support): whether the candidate, aligned coarsely, confirms
  // the feature pose; if so the full-resolution level and the evidence (most of the alignment's
  // time) are skipped. Any candidate, the feature pose's or the registration's, is likewise left
  // at half resolution, hopeless, when the depths there contradict it far beyond what the last
  // level changes (TwoViewOptions::hopeless_consistency_gap): a refused feature pose the depths
  // reject costs the coarse levels only.
  const double hopeless_below = std::min(options.failure_rule.min_registration_consistency,
                                         options.min_depth_only_consistency) -
                                options.hopeless_consistency_gap;
  // Every candidate aligned (hopeless ones too), the feature pose's first.
  std::vector<Candidate> candidates;
  auto evaluate = [&](const std::string& seed, const SE3Quat& T_seed, double fitness,
                      const std::function<bool(const Candidate&)>& settled_coarse) {
    Candidate c;
    c.seed = seed;
    c.T_seed = c.T = T_seed;
    c.fitness = fitness;
    if (options.align_rgbd && settled_coarse && options.rgbd_alignment.levels > 2) {
      // A seed precise enough to be confirmed needs no search from the coarsest level and no
      // polish at half resolution: the confirmation aligns at quarter resolution alone (the
      // feature pairs keep their full-resolution pixels), and ends at steps below 0.06 deg and
      // 1 mm, three times the full alignment's. It asks for 5 deg / 5 cm agreement and depth
      // support, not for the last tenth of a millimetre: on the textbook pair 5.1 -> 2.4 ms.
      // Where it does not confirm, the alignment below runs as it always has.
      RgbdAlignmentOptions quick = options.rgbd_alignment;
      quick.levels -= 1;
      quick.finest_level = 2;
      quick.converged_step = std::max(quick.converged_step, 1e-3);
      const RgbdAlignment a =
          alignRgbdPyramid(pyramid, camera_full.pinhole, T_seed, features_for_alignment, quick);
      r.times_ms.alignment_ms += a.time_ms;
      if (a.ok) {
        c.T = a.T_21;
        measureSupport(&c);
        if (settled_coarse(c)) {
          c.confirms_features = true;
          return c;
        }
        c.T = T_seed;
      }
    }
    if (options.align_rgbd) {
      prepareLevel0();
      RgbdAlignmentOptions o = options.rgbd_alignment;
      if (o.levels > 1) o.finest_level = 1;
      RgbdAlignment a =
          alignRgbdPyramid(pyramid, camera_full.pinhole, T_seed, features_for_alignment, o);
      r.times_ms.alignment_ms += a.time_ms;
      if (a.ok && o.finest_level > 0) {
        c.T = a.T_21;
        measureSupport(&c);
        if (settled_coarse && settled_coarse(c)) {
          c.confirms_features = true;
          return c;
        }
        if (c.consistency < hopeless_below) {
          c.hopeless = true;
          return c;
        }
        // Where an earlier candidate's coarse levels ended, full resolution ends where that one's
        // did (TwoViewOptions::same_coarse_pose_deg): the same pose, not aligned, searched and
        // judged twice. A hopeless one was never judged and is not matched.
        c.T_coarse = a.T_21;
        for (const Candidate& earlier : candidates) {
          if (!earlier.hopeless && earlier.T_coarse &&
              sameCoarsePose(a.T_21, *earlier.T_coarse, options.same_coarse_pose_deg,
                             options.same_coarse_pose_m)) {
            c.duplicate = true;
            return c;
          }
        }
        // Level 0 alone from where the coarse levels stopped: the one alignment over every
        // level, which leaves the seed where it fails.
        o.finest_level = 0;
        o.levels = 1;
        a = alignRgbdPyramid(pyramid, camera_full.pinhole, a.T_21, features_for_alignment, o);
        r.times_ms.alignment_ms += a.time_ms;
        c.T = T_seed;
      }
      if (a.ok) c.T = a.T_21;
    }
    measureSupport(&c);
    slide(&c);
    measureEvidence(&c);
    return c;
  };

  // The registration candidates worth a full alignment (TwoViewOptions::
  // aligned_registration_candidates), in the registration's order: each aligned at quarter
  // resolution alone, from the coarsest level, and the ones the depths support most there kept.
  // A seed 10-15 degrees off the truth still reaches its basin at these levels.
  auto screenedCandidates = [&](const std::vector<DepthRegistration::Candidate>& found) {
    std::vector<size_t> kept(found.size());
    std::iota(kept.begin(), kept.end(), size_t{0});
    const size_t limit = static_cast<size_t>(options.aligned_registration_candidates);
    if (limit == 0 || found.size() <= limit || !options.align_rgbd ||
        options.rgbd_alignment.levels <= 2) {
      return kept;
    }
    // Levels 3 and 2 (80 x 60, 160 x 120) at half the alignment's samples: 1-3 ms a candidate.
    // On the fr3_cabinet key frames five and eight apart the one kept gave the 27 right poses
    // that aligning all eight in full gave (level 3 alone, 26; a quarter of the samples, 25).
    RgbdAlignmentOptions coarse = options.rgbd_alignment;
    coarse.finest_level = 2;
    coarse.finest_stride *= 2;
    coarse.converged_step = std::max(coarse.converged_step, 1e-3);
    // The candidates are independent: aligned side by side (each alignment's iterations are short
    // at these sizes, and its serial part leaves a core idle), each the same on any thread.
    const auto start = Clock::now();
    std::vector<double> support(found.size(), -1.0);
    tbb::parallel_for(size_t{0}, found.size(), [&](size_t k) {
      // A candidate over too small an overlap would be refused (registration_overlap) whatever
      // its alignment: it ranks last, unaligned.
      if (found[k].fitness < options.min_registration_fitness) return;
      const RgbdAlignment a = alignRgbdPyramid(pyramid, camera_full.pinhole, found[k].T_21,
                                               features_for_alignment, coarse);
      if (a.ok) support[k] = consistencyOf(a.T_21, depth1, depth2, camera);
    });
    r.times_ms.alignment_ms += msSince(start);
    std::stable_sort(kept.begin(), kept.end(),
                     [&](size_t a, size_t b) { return support[a] > support[b]; });
    kept.resize(limit);
    std::sort(kept.begin(), kept.end());
    return kept;
  };

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
    auto confirms = [&](const Candidate& c) {
      return supported(c) && !posesDiffer(c.T, features.T_21);
    };
    candidates.push_back(
        cached
            ? cache->candidate
            : evaluate("features", features.T_21, -1.0,
                       stands_if_confirmed ? confirms : std::function<bool(const Candidate&)>()));
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
  auto pairsAgree = [&](const Candidate& c) {
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
       (features.ok && supported(candidates[0]) && !posesDiffer(candidates[0].T, features.T_21)));
  if (conclusive_only && !conclusive) {
    r.failure = "the feature pose alone is not conclusive";
    return r;
  }
  if (!conclusive) {
    DepthRegistrationOptions registration = options.registration;
    registration.covariance = false;  // the alignment's evidence gives the pose's covariance
    const DepthRegistration reg =
        registerDepthImages(depth1, depth2, camera.pinhole, camera.depth_scale, registration);
    r.times_ms.registration_ms = reg.time_ms;
    if (reg.ok) {
      // Every distinct pose the registration found support for that the screening keeps is
      // aligned and judged: a rival the evidence cannot separate from the chosen pose refuses
      // the pair (rival_alignment).
      bool first = true;
      for (size_t k : screenedCandidates(reg.candidates)) {
        Candidate c = evaluate(first ? "registration" : "registration rival",
                               reg.candidates[k].T_21, reg.candidates[k].fitness, {});
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

  r.counts.depth_candidates = static_cast<int>(candidates.size());
  // Which candidate the evidence supports: depth consistency decides when it differs clearly,
  // then photometric agreement, then the feature pairs explained. A pose without feature support
  // rests on the depths alone and must meet the stricter depth-only consistency.
  auto clearlyBetter = [&](const Candidate& a, const Candidate& b) {
    if (supported(a) != supported(b)) return supported(a);
    if (std::abs(a.consistency - b.consistency) > options.clear_consistency_margin) {
      return a.consistency > b.consistency;
    }
    if (std::abs(photometric(a) - photometric(b)) > options.rival_photometric_margin) {
      return photometric(a) > photometric(b);
    }
    return a.explained > b.explained + std::max(3, b.explained / 5);
  };
  size_t best = 0;
  for (size_t i = 1; i < candidates.size(); ++i) {
    const Candidate& a = candidates[i];
    const Candidate& b = candidates[best];
    if (clearlyBetter(a, b) ||
        (!clearlyBetter(b, a) && a.consistency + photometric(a) > b.consistency + photometric(b))) {
      best = i;
    }
  }
  const Candidate& chosen = candidates[best];
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
  if (explainedPairs(r.pairs, chosen.T, stage.geometry, gate, &explained) >=
      options.failure_rule.min_inliers) {
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
        chosen.T, chosen.consistency,
        [&](const SE3Quat& T) { return consistencyOf(T, depth1, depth2, camera); },
        options.covariance.slide_probe_m, options.covariance.slide_consistency_sigma);
    const Eigen::Vector3d above = slideVarianceAbove(slide, r.nominal_covariance);
    r.judged_covariance.bottomRightCorner<3, 3>().diagonal() += above;
    r.covariance.bottomRightCorner<3, 3>().diagonal() += above;
    r.slide_sigma_m = slide;
    r.times_ms.alignment_ms += msSince(start);
  }
  r.depth_consistency = consistencyOf(r.T_21, depth1, depth2, camera);
  r.registration_fitness = chosen.fitness;

  PoseEvidence evidence;
  // The feature-count rules do not apply to a pose the depths carry.
  evidence.pairs = evidence.inliers = std::max(options.failure_rule.min_inliers, 1);
  evidence.chi2_final = 0;
  evidence.depth_consistency = r.depth_consistency;
  evidence.covariance_ok = r.covariance_ok;
  evidence.covariance = r.judged_covariance;
  FailureRule rule = options.failure_rule;
  rule.min_depth_consistency = rule.min_registration_consistency;
  FailureVerdict verdict = rule.check(evidence);
  char text[200];
  if (!verdict.refused() && !supported(chosen) && !featureSupported(chosen)) {
    std::snprintf(text, sizeof text,
                  "depths alone do not settle the pose: consistency %.2f < %.2f with %d feature "
                  "pairs in support",
                  chosen.consistency, options.min_depth_only_consistency, chosen.explained);
    verdict = {"depth_inconsistent", text};
  }
  if (!verdict.refused()) {
    for (size_t i = 0; i < candidates.size(); ++i) {
      const Candidate& c = candidates[i];
      if (i == best || !supported(c) || !posesDiffer(c.T, chosen.T)) continue;
      if (!clearlyBetter(chosen, c)) {
        std::snprintf(text, sizeof text,
                      "rival alignment: the %s pose differs but the evidence supports it nearly "
                      "as well (depth consistency %.2f against %.2f, photometric agreement %.2f "
                      "against %.2f, feature pairs %d against %d)",
                      c.seed.c_str(), c.consistency, chosen.consistency, photometric(c),
                      photometric(chosen), c.explained, chosen.explained);
        verdict = {"rival_alignment", text};
        break;
      }
    }
  }
  // Matched pairs the pose leaves unexplained: with enough of them, a pose that explains almost
  // none contradicts the one measurement the alignment did not rest on.
  if (!verdict.refused() && static_cast<int>(r.pairs.size()) >= options.features_judge_pairs &&
      chosen.explained < options.min_explained_fraction * r.pairs.size()) {
    std::snprintf(text, sizeof text, "the feature pairs contradict the pose: it explains %d of %zu",
                  chosen.explained, r.pairs.size());
    verdict = {"features_disagree", text};
  }
  if (!verdict.refused() && options.align_rgbd &&
      photometric(chosen) < options.min_photometric_agreement) {
    std::snprintf(text, sizeof text,
                  "the aligned images disagree: photometric agreement %.2f < %.2f",
                  photometric(chosen), options.min_photometric_agreement);
    verdict = {"photometric", text};
  }
  if (!verdict.refused() && !r.covariance_ok) {
    verdict = {"degenerate", "degenerate geometry: the depths leave a direction of the pose free"};
  }
  if (!verdict.refused() && chosen.fitness >= 0 &&
      chosen.fitness < options.min_registration_fitness) {
    std::snprintf(text, sizeof text, "registration overlap %.2f < %.2f", chosen.fitness,
                  options.min_registration_fitness);
    verdict = {"registration_overlap", text};
  }
  // Consistency and colour over a sliver of the frame prove little: a pose that explains too
  // small a share of frame 1 is not settled (a scene of a few planes has flipped fits that
  // overlap only at an edge).
  if (!verdict.refused() && chosen.evidence.overlap() < options.min_overlap) {
    std::snprintf(text, sizeof text,
                  "the views overlap too little under the pose: %.0f %% of frame 1 lands on "
                  "frame 2's surfaces (< %.0f %%)",
                  100.0 * chosen.evidence.overlap(), 100.0 * options.min_overlap);
    verdict = {"registration_overlap", text};
  }
  // A rival of the registration's best-supported pose was chosen among up to eight: the more
  // poses tried, the likelier one of them fits a few planes by chance, so it needs more of frame 1.
  const double depth_only_overlap = chosen.rank > 0 ? std::max(options.min_depth_only_overlap,
                                                               options.min_rival_depth_only_overlap)
                                                    : options.min_depth_only_overlap;
  if (!verdict.refused() && !featureSupported(chosen) &&
      chosen.evidence.overlap() < depth_only_overlap) {
    std::snprintf(text, sizeof text,
                  "the depths alone carry the pose and only %.0f %% of frame 1 lands on frame "
                  "2's surfaces (< %.0f %%): a slide or flip of its planes could fit as well",
                  100.0 * chosen.evidence.overlap(), 100.0 * depth_only_overlap);
    verdict = {"registration_overlap", text};
  }
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

}  // namespace pnpba
