#include "depth_path_judging.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace pnpba {

bool featureSupported(const DepthCandidate& c, const TwoViewOptions& options) {
  return c.explained >= options.failure_rule.min_inliers;
}

bool supported(const DepthCandidate& c, const TwoViewOptions& options) {
  return c.consistency >= (featureSupported(c, options)
                               ? options.failure_rule.min_registration_consistency
                               : options.min_depth_only_consistency);
}

bool clearlyBetter(const DepthCandidate& a, const DepthCandidate& b,
                   const TwoViewOptions& options) {
  if (supported(a, options) != supported(b, options)) return supported(a, options);
  if (std::abs(a.consistency - b.consistency) > options.clear_consistency_margin) {
    return a.consistency > b.consistency;
  }
  if (std::abs(photometric(a) - photometric(b)) > options.rival_photometric_margin) {
    return photometric(a) > photometric(b);
  }
  return a.explained > b.explained + std::max(3, b.explained / 5);
}

bool repeatRival(const DepthCandidate& twin, const DepthCandidate& chosen,
                 const TwoViewOptions& options) {
  return twin.consistency >= chosen.consistency - options.repeat_search.rival_consistency_margin &&
         photometric(twin) >= options.min_photometric_agreement;
}

// A twin (repeat_search.h) and the pose it was found from are apart where the twin's alignment
// left them min_shift_m or more apart, or turned apart as posesDiffer counts it: posesDiffer's
// translation bound grows with the translation (a fifth of it), and took a free slide's far end
// 0.65 m along a pose 3.7 m from camera 1 for that pose (the rendered corridor at 45 degrees).
bool twinApart(const DepthCandidate& twin, const DepthCandidate& chosen,
               const TwoViewOptions& options) {
  const SE3Quat relative = twin.T * chosen.T.inverse();
  return relative.translation().norm() >= options.repeat_search.min_shift_m ||
         posesDiffer(twin.T, chosen.T);
}

size_t bestCandidate(const std::vector<DepthCandidate>& candidates, const TwoViewOptions& options) {
  size_t best = 0;
  for (size_t i = 1; i < candidates.size(); ++i) {
    const DepthCandidate& a = candidates[i];
    const DepthCandidate& b = candidates[best];
    if (clearlyBetter(a, b, options) ||
        (!clearlyBetter(b, a, options) &&
         a.consistency + photometric(a) > b.consistency + photometric(b))) {
      best = i;
    }
  }
  return best;
}

FailureVerdict judgeDepthPose(const std::vector<DepthCandidate>& candidates, size_t best,
                              const TwoViewResult& r, const TwoViewOptions& options) {
  const DepthCandidate& chosen = candidates[best];
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
  if (!verdict.refused() && !supported(chosen, options) && !featureSupported(chosen, options)) {
    std::snprintf(text, sizeof text,
                  "depths alone do not settle the pose: consistency %.2f < %.2f with %d feature "
                  "pairs in support",
                  chosen.consistency, options.min_depth_only_consistency, chosen.explained);
    verdict = {"depth_inconsistent", text};
  }
  if (!verdict.refused()) {
    for (size_t i = 0; i < candidates.size(); ++i) {
      const DepthCandidate& c = candidates[i];
      if (i == best || c.hopeless) continue;
      // A twin and the pose it was found from are one period apart whichever of them won the
      // choice: the repeat's margin judges both ways.
      if (c.repeat_twin || chosen.repeat_twin) {
        // A repeat's twin by the repeat's own margin; a free slide's by the evidence's usual
        // ones: a slide the scene leaves free reads the same (the rendered corridor's twins
        // within 0.01), where the rendered cabinet's right pose, 1 % off in fx, read 0.08 above
        // its slid twin and was refused under the repeat's margin.
        const bool rival = c.free_slide || chosen.free_slide
                               ? supported(c, options) && !clearlyBetter(chosen, c, options)
                               : repeatRival(c, chosen, options);
        if (twinApart(c, chosen, options) && rival) {
          std::snprintf(
              text, sizeof text,
              "rival alignment: a twin %.2f m along %s fits nearly as well (depth "
              "consistency %.2f against %.2f, photometric agreement %.2f against %.2f)",
              (c.T * chosen.T.inverse()).translation().norm(),
              c.free_slide || chosen.free_slide ? "a slide the depths leave free" : "a repeat",
              c.consistency, chosen.consistency, photometric(c), photometric(chosen));
          verdict = {"rival_alignment", text};
          break;
        }
        continue;
      }
      if (!posesDiffer(c.T, chosen.T) || !supported(c, options)) continue;
      if (!clearlyBetter(chosen, c, options)) {
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
  if (!verdict.refused() && !featureSupported(chosen, options) &&
      chosen.evidence.overlap() < depth_only_overlap) {
    std::snprintf(text, sizeof text,
                  "the depths alone carry the pose and only %.0f %% of frame 1 lands on frame "
                  "2's surfaces (< %.0f %%): a slide or flip of its planes could fit as well",
                  100.0 * chosen.evidence.overlap(), 100.0 * depth_only_overlap);
    verdict = {"registration_overlap", text};
  }
  return verdict;
}

}  // namespace pnpba
