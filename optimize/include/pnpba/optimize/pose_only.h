// Motion-only bundle adjustment without graph machinery: one SE3 pose against fixed 3-D points
// and their pixels, in fixed-size 6x6 arithmetic over contiguous arrays. The maths and the
// Levenberg-Marquardt steps are those of a SparseOptimizer holding one VertexSE3Expmap and an
// EdgeSE3ProjectXYZOnlyPose per observation (g2o's PoseOptimization graph) on the native back
// end, so the results agree with it to round-off (tests/optimize/pose_only_test.cpp); it runs
// without the per-edge objects, virtual calls and block bookkeeping, on every pair the
// two-view pipeline refines.
//
//   error     e = uv - K(T X),   chi2 = e' (w I) e,   Huber on chi2 when huber_delta > 0
//   update    T <- exp(d) T,     d = [w, v] (DESIGN.md 4)
#pragma once

#include <Eigen/Core>
#include <vector>

#include "pnpba/optimize/edge_se3_project_xyz.h"
#include "pnpba/optimize/se3_quat.h"
#include "pnpba/optimize/sparse_optimizer.h"

namespace pnpba {

// The observations, one entry per index in each array.
struct PoseOnlyProblem {
  PinholeIntrinsics camera;
  std::vector<Eigen::Vector3d> points;  // X, fixed
  std::vector<Eigen::Vector2d> pixels;  // uv
  std::vector<double> information;      // w: the information matrix is w I
  std::vector<char> active;             // 0: left out (g2o: an edge on another level)
  double huber_delta = 0;               // 0: no robust kernel
  void reserve(size_t n) {
    points.reserve(n), pixels.reserve(n), information.reserve(n), active.reserve(n);
  }
  void add(const Eigen::Vector3d& X, const Eigen::Vector2d& uv, double w) {
    points.push_back(X), pixels.push_back(uv), information.push_back(w), active.push_back(1);
  }
  size_t size() const { return points.size(); }
  int numActive() const;
};

// chi2 of observation i at T (without the robust kernel), and whether T X lies in front.
double poseOnlyChi2(const PoseOnlyProblem& p, size_t i, const SE3Quat& T);
bool poseOnlyDepthPositive(const PoseOnlyProblem& p, size_t i, const SE3Quat& T);
// Sum over the active observations of the robust chi2 (the chi2 without a kernel).
double poseOnlyRobustChi2(const PoseOnlyProblem& p, const SE3Quat& T);

// At most `iterations` LM iterations from *T over the active observations, as
// SparseOptimizer::optimize on the native back end (options: tau, user_lambda_init,
// max_trials_after_failure and the two relative decreases). Returns the iterations run.
int optimizePoseOnly(const PoseOnlyProblem& p, SE3Quat* T, int iterations,
                     const OptimizerOptions& options = {});

// Inverse of the (robustly weighted) information at T over the active observations, as
// SparseOptimizer::computeMarginalCovariance; false when it is singular or nothing is active.
bool poseOnlyCovariance(const PoseOnlyProblem& p, const SE3Quat& T, Matrix6d* covariance);

}  // namespace pnpba
