// Two-view RGB-D bundle adjustment without graph machinery: camera 2's pose and the points, camera
// 1 fixed at the identity, over contiguous arrays with one point per vector lane (the two-view
// kernel's loops, optimize/src/two_view_loops.h). The maths and the Levenberg-Marquardt steps are
// those of a SparseOptimizer holding the pipeline's kRgbd graph (pose_graph.h: a VertexSE3Expmap, a
// VertexPointXYZ per point, camera 1's EdgeStereoSE3ProjectXYZ and camera 2's stereo or pinhole
// edge per point) on the native back end, points eliminated by the Schur complement, so the results
// agree with it to round-off (tests/pipeline/pose_rounds_test.cpp); it runs without the per-vertex
// and per-edge objects, virtual calls and block bookkeeping, on every pair the two-view pipeline
// refines.
//
//   camera 1   e1 = (u1, v1, u1 - bf/z1) - S(X)        S: the stereo projection, bf = fx b
//   camera 2   e2 = (u2, v2, u2 - bf/z2) - S(T X)      with depth 2, else (u2, v2) - K(T X)
//   chi2       e' Omega e per error, Huber on it where the problem has a width
//   update     T <- exp(d) T, d = [w, v] (DESIGN.md 4);  X <- X + dX
#pragma once

#include <Eigen/Core>
#include <vector>

#include "pnpba/optimize/edge_stereo_se3_project_xyz.h"
#include "pnpba/optimize/se3_quat.h"
#include "pnpba/optimize/sparse_optimizer.h"

namespace pnpba {

// One point's two observations.
struct RgbdPairObservation {
  Eigen::Vector3d by_camera1 = Eigen::Vector3d::Zero();  // (u1, v1, u1 - bf / z1)
  Eigen::Matrix3d information1 = Eigen::Matrix3d::Identity();
  // Camera 2 with depth 2: (u2, v2, u2 - bf / z2) and its 3x3 information; without: (u2, v2)
  // in the first two entries and the information pixel_information2 * I (2x2).
  bool depth2 = false;
  Eigen::Vector3d by_camera2 = Eigen::Vector3d::Zero();
  Eigen::Matrix3d information2 = Eigen::Matrix3d::Identity();
  double pixel_information2 = 1.0;
};

struct RgbdPairProblem {
  StereoIntrinsics camera;
  std::vector<RgbdPairObservation> observations;
  // Huber widths on chi2's square root (0: no kernel) for the 3-d and the 2-d errors.
  double huber_delta_stereo = 0, huber_delta_pixel = 0;
  // Residual dimensions less the free ones (6 for the pose, 3 per point): the graph's dof (0
  // without observations).
  int degreesOfFreedom() const;
};

struct RgbdPairEstimate {
  SE3Quat T_21;
  std::vector<Eigen::Vector3d> points;  // one per observation, in camera 1's frame
};

// Sum of the robust chi2 of every error at the estimate (the chi2 without a kernel).
double rgbdPairRobustChi2(const RgbdPairProblem& problem, const RgbdPairEstimate& estimate);

// At most `iterations` LM iterations from *estimate, as SparseOptimizer::optimize on the native
// back end (options: tau, user_lambda_init, max_trials_after_failure and the two relative
// decreases). Returns the iterations run (0 without observations). Throws Error when the
// estimate does not hold one point per observation.
int optimizeRgbdPair(const RgbdPairProblem& problem, RgbdPairEstimate* estimate, int iterations,
                     const OptimizerOptions& options = {});

// The pose's marginal covariance at the estimate: the inverse of the (robustly weighted)
// information with the points eliminated, as SparseOptimizer::computeMarginalCovariance; false
// when it is singular or there is no observation.
bool rgbdPairCovariance(const RgbdPairProblem& problem, const RgbdPairEstimate& estimate,
                        Matrix6d* covariance);

}  // namespace pnpba
