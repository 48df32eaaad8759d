#include "pnpba/pipeline/pose_refinement.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "pnpba/core/error.h"
#include "pnpba/optimize/edge_se3_project_xyz.h"
#include "pnpba/optimize/pose_only.h"
#include "pnpba/optimize/vertex_se3_expmap.h"

namespace pnpba {

std::string RefinementOptions::validate() const {
  if (iterations < 1) return "BA iterations must be >= 1";
  if (outlier_rounds < 1) return "outlier rounds must be >= 1";
  if (!(outlier_chi2 > 0)) return "outlier chi2 must be > 0";
  if (!(pixel_sigma > 0)) return "pixel sigma must be > 0";
  if (!(depth_noise_k > 0)) return "depth noise k must be > 0";
  return "";
}

namespace {

PoseGraphOptions graphOptions(BundleMode mode, const PinholeCamera& camera,
                              const RefinementOptions& o) {
  PoseGraphOptions g;
  g.mode = mode;
  g.intrinsics = camera;
  g.intrinsics.distortion = {};
  g.pixel_sigma = o.pixel_sigma;
  g.depth_noise_k = o.depth_noise_k;
  g.depth2_gate_chi2 = o.depth2_gate_chi2;
  return g;
}

void wireLog(SparseOptimizer& optimizer, const RefinementOptions& o, std::ostringstream& buffer) {
  if (!o.verbose || !o.log) return;
  optimizer.setVerbose(true);
  optimizer.setLogStream(&buffer);
}

void flushLog(std::ostringstream& buffer, const RefinementOptions& o) {
  if (!o.log) return;
  std::istringstream lines(buffer.str());
  for (std::string line; std::getline(lines, line);) o.log(line);
  buffer.str("");
}

int degreesOfFreedom(const SparseOptimizer& optimizer) {
  int dof = 0;
  for (const Edge* e : optimizer.activeEdges()) dof += e->dimension();
  for (const Vertex* v : optimizer.activeVertices()) {
    if (!v->fixed()) dof -= v->dimension();
  }
  return dof;
}

const SE3Quat& poseOf(const SparseOptimizer& optimizer) {
  return static_cast<const VertexSE3Expmap*>(optimizer.vertex(PoseGraphIds::kPose))->estimate();
}

// ORB-SLAM's PoseOptimization: rounds of motion-only LM; after each, every pair is classified
// by its chi2 at the new pose (outliers move to level 1, and back when they fit again); the
// Huber kernel is dropped for the last rounds. The covariance is skipped when the rounds only
// pick the inliers of a full BA that reports its own.
Refinement poseRounds(const std::vector<PointPair>& pairs, const SE3Quat& T_init,
                      const PinholeCamera& camera, const RefinementOptions& o,
                      bool want_covariance) {
  SparseOptimizer optimizer;
  optimizer.setSolverBackend(o.solver);
  std::ostringstream log;
  wireLog(optimizer, o, log);
  PoseGraphOptions g = graphOptions(BundleMode::kPose, camera, o);
  g.robust = true;
  buildPoseGraph(optimizer, pairs, T_init, g);
  Refinement r;
  r.inlier.assign(pairs.size(), 1);
  const int per_round = std::max(1, o.iterations / 2);
  for (int round = 0; round < o.outlier_rounds; ++round) {
    optimizer.initializeOptimization(0);
    if (optimizer.activeEdges().size() < 6) break;  // keep the last pose with enough support
    optimizer.computeActiveErrors();
    if (round == 0) r.chi2_initial = optimizer.activeRobustChi2();
    r.iterations += optimizer.optimize(per_round);
    r.solver = toString(optimizer.summary().backend);
    for (size_t i = 0; i < optimizer.edges().size(); ++i) {
      auto* e = static_cast<EdgeSE3ProjectXYZOnlyPose*>(optimizer.edges()[i]);
      e->computeError();
      const bool outlier = e->chi2() > o.outlier_chi2 || !e->isDepthPositive();
      e->setLevel(outlier ? 1 : 0);
      r.inlier[i] = outlier ? 0 : 1;
      if (round == 2) e->setRobustKernel(nullptr);
    }
    flushLog(log, o);
  }
  optimizer.initializeOptimization(0);
  optimizer.computeActiveErrors();
  r.chi2_final = optimizer.activeRobustChi2();
  r.dof = degreesOfFreedom(optimizer);
  r.T_21 = poseOf(optimizer);
  Eigen::MatrixXd cov;
  if (want_covariance && optimizer.activeEdges().size() >= 3 &&
      optimizer.computeMarginalCovariance(PoseGraphIds::kPose, &cov)) {
    r.covariance = cov;
    r.covariance_ok = true;
  }
  r.num_inliers = static_cast<int>(std::count(r.inlier.begin(), r.inlier.end(), 1));
  return r;
}

// poseRounds on the dedicated motion-only solver (pnpba/optimize/pose_only.h): the same
// rounds, classification and results as the graph (tests/pipeline/pose_rounds_test.cpp), at
// a third of the time; it runs on every pair the pipeline refines.
Refinement poseRoundsOnArrays(const std::vector<PointPair>& pairs, const SE3Quat& T_init,
                              const PinholeCamera& camera, const RefinementOptions& o,
                              bool want_covariance) {
  PoseOnlyProblem problem;
  problem.camera = {camera.fx, camera.fy, camera.cx, camera.cy};
  problem.reserve(pairs.size());
  for (const PointPair& pair : pairs) {
    const double s = o.pixel_sigma * pair.sigma_2;
    problem.add(pair.X_1, pair.uv_2, 1.0 / (s * s));
  }
  problem.huber_delta = std::sqrt(5.991);  // pose_graph.cpp's 2-dof Huber width
  Refinement r;
  r.inlier.assign(pairs.size(), 1);
  SE3Quat T = T_init;
  const int per_round = std::max(1, o.iterations / 2);
  for (int round = 0; round < o.outlier_rounds; ++round) {
    if (problem.numActive() < 6) break;  // keep the last pose with enough support
    if (round == 0) r.chi2_initial = poseOnlyRobustChi2(problem, T);
    r.iterations += optimizePoseOnly(problem, &T, per_round);
    for (size_t i = 0; i < pairs.size(); ++i) {
      const bool outlier =
          poseOnlyChi2(problem, i, T) > o.outlier_chi2 || !poseOnlyDepthPositive(problem, i, T);
      problem.active[i] = outlier ? 0 : 1;
      r.inlier[i] = outlier ? 0 : 1;
    }
    if (round == 2) problem.huber_delta = 0;
  }
  r.solver = toString(SolverBackend::kNative);
  r.chi2_final = poseOnlyRobustChi2(problem, T);
  r.dof = 2 * problem.numActive() - 6;
  r.T_21 = T;
  Matrix6d cov;
  if (want_covariance && problem.numActive() >= 3 && poseOnlyCovariance(problem, T, &cov)) {
    r.covariance = cov;
    r.covariance_ok = true;
  }
  r.num_inliers = static_cast<int>(std::count(r.inlier.begin(), r.inlier.end(), 1));
  return r;
}

// The graph engine runs a solve only where its own log or the Ceres back end is asked for; the
// array solvers run the rest.
bool wantsGraph(const RefinementOptions& o) {
  return (o.verbose && o.log) || o.solver == SolverBackend::kCeres;
}

Refinement motionOnlyRounds(const std::vector<PointPair>& pairs, const SE3Quat& T_init,
                            const PinholeCamera& camera, const RefinementOptions& o,
                            bool want_covariance) {
  return wantsGraph(o) ? poseRounds(pairs, T_init, camera, o, want_covariance)
                       : poseRoundsOnArrays(pairs, T_init, camera, o, want_covariance);
}

// The kRgbd graph's solve on the dedicated solver (pnpba/optimize/rgbd_pair.h): the same
// graph, steps and results as solveGraph's (tests/pipeline/pose_rounds_test.cpp) at two thirds of
// its instructions (the graph's objects and virtual calls go, the arithmetic stays); it runs on
// every pair the pipeline refines.
Refinement rgbdOnArrays(const std::vector<PointPair>& pairs, const std::vector<char>& use,
                        const SE3Quat& T_init, const PinholeCamera& camera,
                        const RefinementOptions& o) {
  std::vector<PointPair> kept;
  for (size_t i = 0; i < pairs.size(); ++i)
    if (use[i]) kept.push_back(pairs[i]);
  PoseGraphOptions g = graphOptions(BundleMode::kRgbd, camera, o);
  g.robust = true;
  std::vector<char> depth2_kept;
  const RgbdPairProblem problem = rgbdPairProblem(kept, T_init, g, &depth2_kept);
  RgbdPairEstimate estimate{T_init, {}};
  estimate.points.reserve(kept.size());
  for (const PointPair& pair : kept) estimate.points.push_back(pair.X_1);
  Refinement r;
  r.chi2_initial = rgbdPairRobustChi2(problem, estimate);
  r.iterations = optimizeRgbdPair(problem, &estimate, o.iterations * 5);
  r.solver = toString(SolverBackend::kNative);
  r.chi2_final = rgbdPairRobustChi2(problem, estimate);
  r.dof = problem.degreesOfFreedom();
  r.T_21 = estimate.T_21;
  r.inlier = use;
  r.num_inliers = static_cast<int>(kept.size());
  r.depth2.assign(pairs.size(), 0);
  for (size_t i = 0, k = 0; i < pairs.size(); ++i)
    if (use[i]) r.depth2[i] = depth2_kept[k++];
  Matrix6d cov;
  if (rgbdPairCovariance(problem, estimate, &cov)) {
    r.covariance = cov;
    r.covariance_ok = true;
  }
  return r;
}

// One solve of the graph of `mode` over the pairs flagged in `use`.
Refinement solveGraph(const std::vector<PointPair>& pairs, const std::vector<char>& use,
                      const SE3Quat& T_init, const PinholeCamera& camera, BundleMode mode,
                      bool robust, const RefinementOptions& o) {
  std::vector<PointPair> kept;
  for (size_t i = 0; i < pairs.size(); ++i)
    if (use[i]) kept.push_back(pairs[i]);
  SparseOptimizer optimizer;
  optimizer.setSolverBackend(o.solver);
  std::ostringstream log;
  wireLog(optimizer, o, log);
  PoseGraphOptions g = graphOptions(mode, camera, o);
  g.robust = robust;
  const PoseGraphIds ids = buildPoseGraph(optimizer, kept, T_init, g);
  optimizer.initializeOptimization();
  optimizer.computeActiveErrors();
  Refinement r;
  r.chi2_initial = optimizer.activeRobustChi2();
  r.iterations = optimizer.optimize(o.iterations * 5);  // full BA: let LM converge
  flushLog(log, o);
  r.solver = toString(optimizer.summary().backend);
  r.chi2_final = optimizer.activeRobustChi2();
  r.dof = degreesOfFreedom(optimizer);
  r.T_21 = poseOf(optimizer);
  r.inlier = use;
  r.num_inliers = static_cast<int>(std::count(use.begin(), use.end(), 1));
  if (!ids.depth2.empty()) {
    r.depth2.assign(pairs.size(), 0);
    for (size_t i = 0, k = 0; i < pairs.size(); ++i)
      if (use[i]) r.depth2[i] = ids.depth2[k++];
  }
  // The textbook graphs leave points (textbook) or the scale (two-camera) unobservable: their
  // information is singular, so no covariance is reported for them.
  if (mode != BundleMode::kRgbd) return r;
  Eigen::MatrixXd cov;
  if (optimizer.computeMarginalCovariance(PoseGraphIds::kPose, &cov)) {
    r.covariance = cov;
    r.covariance_ok = true;
  }
  return r;
}

}  // namespace

Refinement refinePose(const std::vector<PointPair>& pairs, const SE3Quat& T_init,
                      const PinholeCamera& camera, const RefinementOptions& options) {
  const std::string problem = options.validate();
  if (!problem.empty()) throw Error(problem);
  const std::vector<char> all(pairs.size(), 1);
  switch (options.mode) {
    case BundleMode::kNone: {
      RefinementOptions zero = options;
      zero.verbose = false;
      // Evaluate, not optimise: one pose-only graph at the initial pose.
      SparseOptimizer optimizer;
      buildPoseGraph(optimizer, pairs, T_init, graphOptions(BundleMode::kPose, camera, zero));
      optimizer.initializeOptimization();
      optimizer.computeActiveErrors();
      Refinement r;
      r.T_21 = T_init;
      r.chi2_initial = r.chi2_final = optimizer.chi2();
      r.dof = degreesOfFreedom(optimizer);
      r.solver = "none";
      r.inlier = all;
      r.num_inliers = static_cast<int>(pairs.size());
      Eigen::MatrixXd cov;
      if (optimizer.computeMarginalCovariance(PoseGraphIds::kPose, &cov)) {
        r.covariance = cov;
        r.covariance_ok = true;
      }
      return r;
    }
    case BundleMode::kPose:
      return motionOnlyRounds(pairs, T_init, camera, options, true);
    case BundleMode::kTextbook:
    case BundleMode::kTwoCamera:
      return solveGraph(pairs, all, T_init, camera, options.mode, false, options);
    case BundleMode::kRgbd: {
      const Refinement rounds = motionOnlyRounds(pairs, T_init, camera, options, false);
      return wantsGraph(options) ? solveGraph(pairs, rounds.inlier, rounds.T_21, camera,
                                              BundleMode::kRgbd, true, options)
                                 : rgbdOnArrays(pairs, rounds.inlier, rounds.T_21, camera, options);
    }
  }
  throw Error("unknown BA mode");
}

}  // namespace pnpba
