// bundle_adjust_pairs' work as one library call: two-view bundle adjustment of 3D-2D pairs with
// any of the BA graphs (pose_graph.h) and either back end, started from a given pose or from
// the motion-only least-squares pose solved from the identity.
#pragma once

#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "pnpba/pipeline/pose_graph.h"

namespace pnpba {

struct PairsAdjustmentOptions {
  PoseGraphOptions graph;
  SolverBackend backend = SolverBackend::kAuto;
  int iterations = 100;
  std::optional<SE3Quat> start;  // none: motion-only LS from the identity
  std::ostream* log = nullptr;   // g2o-style per-iteration log of the main solve, if set
  std::string validate() const;  // empty when valid
};

struct PairsAdjustment {
  bool ok = false;  // false: fewer than 6 pairs, or the solve diverged
  std::string failure;
  SE3Quat T_initial, T_21;
  double chi2_initial = 0, chi2_final = 0;
  OptimizationSummary summary;
};

// The start pose adjustPairs uses: options.start, else the motion-only least-squares pose
// solved from the identity.
SE3Quat pairsStartPose(const std::vector<PointPair>& pairs, const PairsAdjustmentOptions& options);

// Throws Error for invalid options or a graph the pairs cannot build (e.g. a two-camera mode
// without image-1 pixels).
PairsAdjustment adjustPairs(const std::vector<PointPair>& pairs,
                            const PairsAdjustmentOptions& options);

std::string pairsAdjustmentJson(const PairsAdjustment& result, size_t num_pairs,
                                const std::string& mode);

}  // namespace pnpba
