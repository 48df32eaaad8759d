#include "pnpba/pipeline/pairs_adjustment.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "pnpba/core/error.h"
#include "pnpba/optimize/vertex_se3_expmap.h"

namespace pnpba {

namespace {

struct Solve {
  SE3Quat T;
  OptimizationSummary summary;
  double chi2_before = 0, chi2_after = 0;
};

Solve solve(const std::vector<PointPair>& pairs, const SE3Quat& start,
            const PoseGraphOptions& graph, SolverBackend backend, int iterations,
            std::ostream* log) {
  SparseOptimizer optimizer;
  optimizer.setSolverBackend(backend);
  optimizer.setVerbose(log != nullptr);
  if (log != nullptr) optimizer.setLogStream(log);
  buildPoseGraph(optimizer, pairs, start, graph);
  optimizer.initializeOptimization();
  optimizer.computeActiveErrors();
  Solve s;
  s.chi2_before = optimizer.chi2();
  optimizer.optimize(iterations);
  s.chi2_after = optimizer.chi2();
  s.summary = optimizer.summary();
  s.T = static_cast<VertexSE3Expmap*>(optimizer.vertex(PoseGraphIds::kPose))->estimate();
  return s;
}

nlohmann::json matrixJson(const Eigen::Matrix4d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return rows;
}

}  // namespace

std::string PairsAdjustmentOptions::validate() const {
  if (iterations < 1) return "iterations must be >= 1";
  return graph.validate();
}

SE3Quat pairsStartPose(const std::vector<PointPair>& pairs, const PairsAdjustmentOptions& options) {
  if (options.start) return *options.start;
  PoseGraphOptions pose_only = options.graph;
  pose_only.mode = BundleMode::kPose;
  return solve(pairs, SE3Quat(), pose_only, options.backend, options.iterations, nullptr).T;
}

PairsAdjustment adjustPairs(const std::vector<PointPair>& pairs,
                            const PairsAdjustmentOptions& options) {
  const std::string invalid = options.validate();
  if (!invalid.empty()) throw Error(invalid);
  PairsAdjustment result;
  if (pairs.size() < 6) {
    result.failure = std::to_string(pairs.size()) + " pairs < 6 required";
    return result;
  }
  result.T_initial = pairsStartPose(pairs, options);
  const Solve s = solve(pairs, result.T_initial, options.graph, options.backend, options.iterations,
                        options.log);
  result.T_21 = s.T;
  result.chi2_initial = s.chi2_before;
  result.chi2_final = s.chi2_after;
  result.summary = s.summary;
  result.ok = std::isfinite(s.chi2_after) && s.T.to_homogeneous_matrix().allFinite();
  if (!result.ok) result.failure = "optimisation diverged";
  return result;
}

std::string pairsAdjustmentJson(const PairsAdjustment& r, size_t num_pairs,
                                const std::string& mode) {
  nlohmann::json j;
  j["ok"] = r.ok;
  if (!r.ok) j["failure"] = r.failure;
  j["pairs"] = num_pairs;
  j["mode"] = mode;
  j["solver"] = toString(r.summary.backend);
  j["iterations"] = r.summary.iterations;
  j["termination"] = r.summary.termination;
  j["time_s"] = r.summary.time_s;
  if (r.ok) {
    j["chi2_initial"] = r.chi2_initial;
    j["chi2_final"] = r.chi2_final;
    j["T_initial"] = matrixJson(r.T_initial.to_homogeneous_matrix());
    j["T"] = matrixJson(r.T_21.to_homogeneous_matrix());
  }
  return j.dump(2) + "\n";
}

}  // namespace pnpba
