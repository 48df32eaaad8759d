#include "depth_candidates.h"

#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "depth_path_judging.h"
#include "pnpba/pipeline/alignment_evidence.h"
#include "pnpba/pipeline/slide_search.h"

namespace pnpba {

namespace {

// Whether two poses the alignment's coarse levels ended at lie within the given bounds
// (TwoViewOptions::same_coarse_pose_deg, same_coarse_pose_m), measured as posesDiffer measures.
bool sameCoarsePose(const SE3Quat& a, const SE3Quat& b, double max_deg, double max_m) {
  const double angle = Eigen::AngleAxisd(a.rotation() * b.rotation().inverse()).angle();
  return angle < max_deg * M_PI / 180.0 && (a.translation() - b.translation()).norm() < max_m;
}

}  // namespace

CandidateAligner::CandidateAligner(const DepthPathView& view, RecycledPyramid* pyramid,
                                   const PinholeCamera& camera_full, const Correspondences& pairs,
                                   const FeatureStage& stage, const TwoViewOptions& options,
                                   double* alignment_ms, TimeBudget* budget)
    : view_(view),
      recycled_(*pyramid),
      camera_full_(camera_full),
      scorer_(pairs, stage.geometry),
      stage_(stage),
      options_(options),
      alignment_ms_(alignment_ms),
      hopeless_below_(std::min(options.failure_rule.min_registration_consistency,
                               options.min_depth_only_consistency) -
                      options.hopeless_consistency_gap),
      budget_(budget),
      deadline_(budget->deadline()) {
  for (const Correspondence& c : pairs) {
    features_.push_back({c.X_1, c.uv_2, keypointSigma(stage.f2, c.keypoint_2, options)});
  }
}

double CandidateAligner::consistencyAt(const SE3Quat& T) const {
  return consistencyOf(T, view_.depth1, view_.depth2, view_.camera);
}

int CandidateAligner::explainedPairs(const SE3Quat& T, std::vector<char>* explained) const {
  const double gate_px = 4.0 * options_.ransac.threshold_px;
  std::vector<double> e2;
  scorer_.squaredErrors(T, &e2);
  explained->assign(e2.size(), 0);
  int n = 0;
  for (size_t i = 0; i < e2.size(); ++i) n += (*explained)[i] = e2[i] < gate_px * gate_px;
  return n;
}

// A candidate's evidence at its pose: what the depths and the feature pairs say (cheap).
void CandidateAligner::measureSupport(DepthCandidate* c) {
  const auto start = Clock::now();
  c->consistency = consistencyAt(c->T);
  std::vector<char> unused;
  c->explained = explainedPairs(c->T, &unused);
  *alignment_ms_ += msSince(start);
}

// Level 0's gradients, the first time an alignment or evidence works at full resolution.
void CandidateAligner::prepareLevel0() {
  const auto start = Clock::now();
  prepareFullResolution(&recycled_.levels);
  *alignment_ms_ += msSince(start);
}

RgbdAlignment CandidateAligner::align(const SE3Quat& T_seed, const RgbdAlignmentOptions& o,
                                      DepthCandidate* c) {
  RgbdAlignment a =
      alignRgbdPyramid(recycled_.levels, camera_full_, T_seed, features_, o, deadline_);
  *alignment_ms_ += a.time_ms;
  c->out_of_time = c->out_of_time || a.out_of_time;
  return a;
}

// The alignment's own evidence (photometric agreement, overlap, information) at full resolution.
void CandidateAligner::measureEvidence(DepthCandidate* c) {
  prepareLevel0();
  const auto start = Clock::now();
  c->evidence = measureAlignmentAt(recycled_.levels[0], camera_full_, c->T, features_,
                                   options_.alignment_evidence);
  *alignment_ms_ += msSince(start);
}

// A supported but not conclusive candidate may rest along a plain wall, where the alignment
// cannot see a slide (slide_search.h): a shift the depths support better is aligned again, and
// the new pose replaces it when the depths support that better by the same margin. Only a pose
// the depths already support is searched, so no refusal becomes an answer by it.
void CandidateAligner::slide(DepthCandidate* c) {
  if (!options_.align_rgbd || !(options_.slide_search.step_m > 0) || !supported(*c, options_) ||
      c->consistency >= options_.conclusive_consistency) {
    return;
  }
  const auto start = Clock::now();
  const SlideSeed seed = findSlideSeed(
      c->T, c->consistency, [&](const SE3Quat& T) { return consistencyAt(T); },
      options_.slide_search);
  *alignment_ms_ += msSince(start);
  if (!seed.found) return;
  // Aligned again from the seed down to half resolution first: a seed the alignment pulls back
  // (on the rendered sweep and the real cabinet frames, every one found with the exact
  // calibration) stops there, at a quarter of the full alignment's cost; one that holds more
  // than the candidate's consistency goes on to full resolution, which together is the one
  // alignment over every level.
  prepareLevel0();
  RgbdAlignmentOptions o = options_.rgbd_alignment;
  if (o.levels > 1) o.finest_level = 1;
  RgbdAlignment a = align(seed.T, o, c);
  if (!a.ok) return;
  DepthCandidate moved = *c;
  if (o.finest_level > 0) {
    moved.T = a.T_21;
    measureSupport(&moved);
    if (!(moved.consistency > c->consistency)) return;
    o.finest_level = 0;
    o.levels = 1;
    a = align(a.T_21, o, c);
    if (!a.ok) return;
  }
  moved.T = a.T_21;
  measureSupport(&moved);
  if (supported(moved, options_) &&
      moved.consistency >= c->consistency + options_.slide_search.min_gain) {
    *c = moved;
  }
}

// `settled_coarse(c)` (given c's support): whether the candidate, aligned coarsely, confirms the
// feature pose; if so the full-resolution level and the evidence (most of the alignment's time)
// are skipped. Any candidate, the feature pose's or the registration's, is likewise left at half
// resolution, hopeless, when the depths there contradict it far beyond what the last level
// changes (TwoViewOptions::hopeless_consistency_gap): a refused feature pose the depths reject
// costs the coarse levels only.
DepthCandidate CandidateAligner::evaluate(
    const std::string& seed, const SE3Quat& T_seed, double fitness,
    const std::function<bool(const DepthCandidate&)>& settled_coarse,
    const std::vector<DepthCandidate>& earlier) {
  DepthCandidate c;
  c.seed = seed;
  c.T_seed = c.T = T_seed;
  c.fitness = fitness;
  if (options_.align_rgbd && settled_coarse && options_.rgbd_alignment.levels > 2) {
    // A seed precise enough to be confirmed needs no search from the coarsest level and no
    // polish at half resolution: the confirmation aligns at quarter resolution alone (the
    // feature pairs keep their full-resolution pixels), and ends at steps below 0.06 deg and
    // 1 mm, three times the full alignment's. It asks for 5 deg / 5 cm agreement and depth
    // support, not for the last tenth of a millimetre: on the textbook pair 5.1 -> 2.4 ms.
    // Where it does not confirm, the alignment below runs as it always has.
    RgbdAlignmentOptions quick = options_.rgbd_alignment;
    quick.levels -= 1;
    quick.finest_level = 2;
    quick.converged_step = std::max(quick.converged_step, 1e-3);
    const RgbdAlignment a = align(T_seed, quick, &c);
    if (c.out_of_time) return c;
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
  if (options_.align_rgbd) {
    prepareLevel0();
    RgbdAlignmentOptions o = options_.rgbd_alignment;
    if (o.levels > 1) o.finest_level = 1;
    RgbdAlignment a = align(T_seed, o, &c);
    if (c.out_of_time) return c;
    if (a.ok && o.finest_level > 0) {
      c.T = a.T_21;
      measureSupport(&c);
      if (settled_coarse && settled_coarse(c)) {
        c.confirms_features = true;
        return c;
      }
      if (c.consistency < hopeless_below_) {
        c.hopeless = true;
        return c;
      }
      // Where an earlier candidate's coarse levels ended, full resolution ends where that one's
      // did (TwoViewOptions::same_coarse_pose_deg): the same pose, not aligned, searched and
      // judged twice. A hopeless one was never judged and is not matched.
      c.T_coarse = a.T_21;
      for (const DepthCandidate& e : earlier) {
        if (!e.hopeless && e.T_coarse &&
            sameCoarsePose(a.T_21, *e.T_coarse, options_.same_coarse_pose_deg,
                           options_.same_coarse_pose_m)) {
          c.duplicate = true;
          return c;
        }
      }
      // Level 0 alone from where the coarse levels stopped: the one alignment over every
      // level, which leaves the seed where it fails.
      o.finest_level = 0;
      o.levels = 1;
      a = align(a.T_21, o, &c);
      if (c.out_of_time) return c;
      c.T = T_seed;
    }
    if (a.ok) c.T = a.T_21;
  }
  measureSupport(&c);
  slide(&c);
  // The evidence is measured in one piece (2-4 ms at 640 x 480): it starts only where it fits.
  if (c.out_of_time || !budget_->allows(BudgetedStage::kEvidence)) {
    c.out_of_time = true;
    return c;
  }
  const auto evidence_start = Clock::now();
  measureEvidence(&c);
  budget_->record(BudgetedStage::kEvidence, msSince(evidence_start));
  return c;
}

// Each aligned at quarter resolution alone, from the coarsest level, and the ones the depths
// support most there kept. A seed 10-15 degrees off the truth still reaches its basin at these
// levels.
std::vector<size_t> CandidateAligner::screened(
    const std::vector<DepthRegistration::Candidate>& found) {
  std::vector<size_t> kept(found.size());
  std::iota(kept.begin(), kept.end(), size_t{0});
  const size_t limit = static_cast<size_t>(options_.aligned_registration_candidates);
  if (limit == 0 || found.size() <= limit || !options_.align_rgbd ||
      options_.rgbd_alignment.levels <= 2) {
    return kept;
  }
  // Levels 3 and 2 (80 x 60, 160 x 120) at half the alignment's samples: 1-3 ms a candidate.
  // On the fr3_cabinet key frames five and eight apart the one kept gave the 27 right poses
  // that aligning all eight in full gave (level 3 alone, 26; a quarter of the samples, 25).
  RgbdAlignmentOptions coarse = options_.rgbd_alignment;
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
    if (found[k].fitness < options_.min_registration_fitness) return;
    const RgbdAlignment a = alignRgbdPyramid(recycled_.levels, camera_full_, found[k].T_21,
                                             features_, coarse, deadline_);
    if (a.ok) support[k] = consistencyAt(a.T_21);
  });
  *alignment_ms_ += msSince(start);
  std::stable_sort(kept.begin(), kept.end(),
                   [&](size_t a, size_t b) { return support[a] > support[b]; });
  kept.resize(limit);
  std::sort(kept.begin(), kept.end());
  return kept;
}

}  // namespace pnpba
