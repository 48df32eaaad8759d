// Bundle adjustment of an initial T_21 over 3D-2D pairs, in one of the BA modes:
//   kNone       the initial pose, with its pose-only chi2 and covariance;
//   kPose       ORB-SLAM's PoseOptimization: motion-only, Huber, outlier rounds that move
//               pairs with chi2 > 5.991 (95%, 2 dof) out and back in;
//   kTextbook, kTwoCamera   the textbook's graphs (no outlier handling: parity and teaching);
//   kRgbd       outliers decided by the kPose rounds on the image-2 residual (where they are
//               visible: NOTES-accuracy.md), then the pixel-and-depth graph of pose_graph.h on
//               the inliers, Huber kernels, depth 2 where given and consistent.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "pnpba/optimize/sparse_optimizer.h"
#include "pnpba/pipeline/pose_graph.h"

namespace pnpba {

struct RefinementOptions {
  BundleMode mode = BundleMode::kRgbd;
  SolverBackend solver = SolverBackend::kAuto;
  int iterations = 20;          // LM iterations of the final solve (and per outlier round / 2)
  int outlier_rounds = 4;       // ORB-SLAM: 4 rounds of 10 iterations
  double outlier_chi2 = 5.991;  // chi2(2 dof, 95%)
  double pixel_sigma = 1.0;
  double depth_noise_k = 0.003;
  double depth2_gate_chi2 = 9.0;
  bool verbose = false;                         // g2o-style log through `log`
  std::function<void(const std::string&)> log;  // receives whole lines
  std::string validate() const;
};

struct Refinement {
  SE3Quat T_21;
  double chi2_initial = 0, chi2_final = 0;  // of the final graph, before and after
  // Degrees of freedom of the final graph: residual dimensions of its active edges minus the
  // dimensions of its free vertices (chi2_final / dof is the fit's variance factor).
  int dof = 0;
  int iterations = 0;
  std::string solver;        // back end that ran
  std::vector<char> inlier;  // per pair, after the outlier rounds
  std::vector<char> depth2;  // kRgbd: per pair, whether the final graph used its depth 2
  int num_inliers = 0;
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool covariance_ok = false;
};

Refinement refinePose(const std::vector<PointPair>& pairs, const SE3Quat& T_init,
                      const PinholeCamera& camera, const RefinementOptions& options);

}  // namespace pnpba
