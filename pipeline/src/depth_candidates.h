// The depth path's candidates (depth_path.cpp runs them): each pose seed refined by the direct
// RGB-D alignment on the pair's working view and pyramid, then measured for the evidence it is
// judged by (depth_path_judging.h). Cheap before costly: a seed that confirms the feature pose
// stops at quarter resolution, one the depths contradict at half resolution stops there
// (hopeless), and one whose coarse levels end where an earlier candidate's did is that one again
// (duplicate); only the rest are aligned at full resolution, searched for a slide and measured.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "pnpba/pipeline/depth_registration.h"
#include "pnpba/pipeline/rgbd_alignment.h"
#include "reprojection_scorer.h"
#include "rgbd_residuals.h"
#include "time_budget.h"
#include "two_view_stages.h"

namespace pnpba {

class CandidateAligner {
 public:
  // `pyramid` is built (rgbdPyramidInto) from `view`; its full-resolution level is prepared on
  // first use. `camera_full` is the camera of the feature pairs' pixels. Every stage's time adds
  // to *alignment_ms. Each alignment stops at the budget's deadline, the evidence starts only
  // where it fits, and a candidate either stopped is returned out_of_time (time_budget.h).
  CandidateAligner(const DepthPathView& view, RecycledPyramid* pyramid,
                   const PinholeCamera& camera_full, const Correspondences& pairs,
                   const FeatureStage& stage, const TwoViewOptions& options, double* alignment_ms,
                   TimeBudget* budget);

  // The candidate seeded at T_seed (`seed` names it; `fitness`: the registration's overlap, -1
  // for the feature pose), aligned and measured. `settled_coarse`, where given, is asked after
  // the quarter- and the half-resolution alignment whether the candidate confirms the feature
  // pose (then it stops there, confirms_features). `earlier`: the candidates before it.
  DepthCandidate evaluate(const std::string& seed, const SE3Quat& T_seed, double fitness,
                          const std::function<bool(const DepthCandidate&)>& settled_coarse,
                          const std::vector<DepthCandidate>& earlier);

  // The registration candidates worth a full alignment (TwoViewOptions::
  // aligned_registration_candidates), indices in the registration's order. Past the deadline
  // the ranking is incomplete: the caller asks the budget before using it.
  std::vector<size_t> screened(const std::vector<DepthRegistration::Candidate>& found);

  // The depth consistency of both working depth images at T.
  double consistencyAt(const SE3Quat& T) const;

  // The feature pairs T explains (projected within 4 RANSAC thresholds; flags into *explained)
  // and their count.
  int explainedPairs(const SE3Quat& T, std::vector<char>* explained) const;

 private:
  void measureSupport(DepthCandidate* c);
  void prepareLevel0();
  void measureEvidence(DepthCandidate* c);
  void slide(DepthCandidate* c);
  // The alignment to the deadline; *c out_of_time where it stopped there.
  RgbdAlignment align(const SE3Quat& T_seed, const RgbdAlignmentOptions& o, DepthCandidate* c);

  const DepthPathView& view_;
  RecycledPyramid& recycled_;
  const PinholeCamera& camera_full_;
  ReprojectionScorer scorer_;  // the feature pairs, laid out once for every pose measured
  const FeatureStage& stage_;
  const TwoViewOptions& options_;
  double* alignment_ms_;
  std::vector<AlignmentFeature> features_;  // the feature pairs, as the alignment joins them
  double hopeless_below_;                   // the depth consistency at half resolution
  TimeBudget* budget_;
  Clock::time_point deadline_;
};

}  // namespace pnpba
