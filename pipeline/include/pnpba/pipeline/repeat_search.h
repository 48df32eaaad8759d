// Whether a pose the depths alone carry has a twin one period along a repeat. A structure whose
// geometry repeats (a zig-zag of panels, shelving, a row of pillars, a corridor) fits the depths
// as well shifted by a whole period, everywhere but at its ends, and plain colour repeats with
// it. The global registration may return either, and where it offers only one, no rival shows:
// on the rendered zig-zag (SceneLayout::kStructure, 3 seeds) 28 of 108 pairs were returned one
// period (1.2 m) off, at depth consistency 0.96-0.99 and photometric agreement 0.86-1.00.
//
// The search shifts the scene camera 1 sees (a right translation of T_21: X2 = R (X1 + d) + t)
// along camera 1's x, y and z and the two diagonals between x and z, from min_shift_m to
// max_shift_m either way. On each of these rays it takes the most consistent shift beyond a dip
// (a second peak: min_dip), looks a quarter and half a step either side of it, and keeps it as a
// twin where its consistency is within consistency_margin of T_21's own and it agrees over at
// least min_agree_ratio of the samples T_21 agrees over. A twin is a seed to align and judge as
// a rival, never an answer by itself (depth_path.cpp).
//
// A slide the depths leave free is found the same way. Along a plain wall on a plain floor (a
// corridor with plain walls) neither the depths nor the colours change however far the scene
// slides along them: the colours' one edge, where the wall meets the floor, runs along the
// slide. On the rendered corridor (SceneLayout::kCorridor, 3 seeds) the depth path returned 49
// of 108 poses 0.5-4 m off along the wall at consistency 0.96-0.99 and photometric agreement
// 0.94-1.00, reporting a translation 1-sigma of 5-15 cm (the alignment's information reads
// sensor noise on plain faces as texture). A ray whose every shift out to free_slide_m keeps the
// pose's consistency is such a slide, and its first shift that far is a twin as well (of all
// free slides, the most consistent one's). Besides the fixed rays, the caller may name the
// directions its pose is loosest along: the free one need not lie along camera 1's axes.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "pnpba/optimize/se3_quat.h"
#include "pnpba/pipeline/depth_consistency.h"

namespace pnpba {

struct RepeatSearchOptions {
  double min_shift_m = 0.3;  // nearer shifts are a slide (slide_search.h), not a repeat
  double max_shift_m = 2.0;  // 0: no search
  double step_m = 0.08;      // between shifts; each peak is then looked at step / 4 either side
  // Unaligned, a twin reads below its aligned self (its pose keeps T_21's rotation error), hence
  // a margin wider than the evidence's clear_consistency_margin.
  double consistency_margin = 0.05;
  double min_agree_ratio = 0.5;
  // Some nearer shift on the same ray read at least this much less consistency than the twin: a
  // repeat's twin is a second peak, where a slide along a plain plane only falls away.
  double min_dip = 0.1;
  // A ray whose every shift from min_shift_m out to this keeps T_21's consistency (within
  // consistency_margin, agreeing over min_agree_ratio) is a free slide: its first shift that far
  // is a twin (0: no free slides; at most max_shift_m).
  double free_slide_m = 0.6;
  int stride = 32;    // the consistency's pixel stride for the search (every 32nd: ~600 samples)
  int max_twins = 2;  // the most consistent, one per ray at most
  // An aligned twin is a rival (the pair refused) while its depth consistency stays within this
  // of the chosen pose's and its colours agree (TwoViewOptions::min_photometric_agreement): one
  // period apart the depths differ only in which points are in view, and on the rendered
  // zig-zag the far, coarsely quantised ones moved the truth's consistency 0.01-0.08 below its
  // twin's.
  double rival_consistency_margin = 0.1;
  std::string validate() const;  // empty when valid
};

struct RepeatTwin {
  SE3Quat T;                                        // T_21 with the scene shifted
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();  // d, in camera 1 (m)
  double consistency = 0;
  double agree_ratio = 0;   // its agreeing samples over T_21's
  bool free_slide = false;  // the far end of a free slide, not a second peak
};

// measure(T): the depth consistency of both depth images at T at options.stride; it is called
// from several threads at once (TBB, on the cores there are). `loose`: further directions in
// camera 1 to search along, both ways (unit or not; a zero vector is skipped). Twins most
// consistent first, at most max_twins, none within min_shift_m of another.
std::vector<RepeatTwin> findRepeatTwins(
    const SE3Quat& T, const std::function<DepthConsistency(const SE3Quat&)>& measure,
    const RepeatSearchOptions& options, const std::vector<Eigen::Vector3d>& loose = {});

}  // namespace pnpba
