// The depth path's judgement (depth_path.cpp runs it): which aligned candidate the evidence
// supports, and which refusal fires for it. Every rule reads evidence the alignment did not
// optimise: the depth consistency of both depth images, the photometric agreement, the overlap,
// the feature pairs the pose explains, the information.
//
//   the chosen candidate                                      refused as
//   --------------------------------------------------------  ---------------------------
//   the depths contradict it (< 0.9), or carry it alone        depth_inconsistent
//   (< 20 feature pairs) below 0.95
//   another supported candidate differs and the evidence       rival_alignment
//   does not separate the two (clearlyBetter), or, a twin one
//   period along a repeat on either side, the twin reads nearly
//   its consistency and its colours agree (repeatRival); or the
//   twin at a free slide's far end, 0.3 m or more away, is not
//   separated from it (clearlyBetter)
//   it explains < 5 % of 20 or more feature pairs              features_disagree
//   its aligned images correlate below 0.7                     photometric
//   the information leaves a direction free                    degenerate
//   the registration or the pose covers too little: a pose     registration_overlap
//   the depths alone carry needs a quarter of frame 1 (a
//   slide or flip of a few planes fits as well over a sliver)
#pragma once

#include <vector>

#include "pnpba/pipeline/failure_rule.h"
#include "two_view_stages.h"

namespace pnpba {

inline double photometric(const DepthCandidate& c) { return c.evidence.photometric_agreement; }

// Enough feature pairs explained for the feature-count rules to apply.
bool featureSupported(const DepthCandidate& c, const TwoViewOptions& options);
// The depths support it: the registration's consistency bound where feature pairs back it, the
// stricter depth-only one where the depths alone carry it.
bool supported(const DepthCandidate& c, const TwoViewOptions& options);
// a clearly better than b: supported against not, then depth consistency when it differs
// clearly, then photometric agreement, then the feature pairs explained.
bool clearlyBetter(const DepthCandidate& a, const DepthCandidate& b, const TwoViewOptions& options);
// A twin one period along a repeat (repeat_search.h) that the evidence does not rule out beside
// `chosen`: its consistency within the repeat's margin, its colours agreeing.
bool repeatRival(const DepthCandidate& twin, const DepthCandidate& chosen,
                 const TwoViewOptions& options);
// The index of the candidate the evidence supports (the first when nothing separates them).
size_t bestCandidate(const std::vector<DepthCandidate>& candidates, const TwoViewOptions& options);

// The refusal for candidates[best], whose pose `r` holds with its covariance and depth
// consistency (the table above), r.pairs the feature pairs; an empty verdict when it stands.
FailureVerdict judgeDepthPose(const std::vector<DepthCandidate>& candidates, size_t best,
                              const TwoViewResult& r, const TwoViewOptions& options);

}  // namespace pnpba
