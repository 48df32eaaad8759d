// Direct (photometric) bundle adjustment of camera poses and points (the exercise's data
// format) on EdgePhotometric graphs, with the active set of edges decided per round.
//
// Files: poses "timestamp tx ty tz qx qy qz qw" (T_cw, world -> camera; the timestamp text is
// kept as written), points "x y z" (world) then the 16 intensities of the point's 4x4 patch,
// k = 4 (dx + 2) + (dy + 2).
#pragma once

#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "pnpba/direct/photometric_edge.h"
#include "pnpba/optimize/sparse_optimizer.h"

namespace pnpba {

struct DirectPose {
  std::string stamp;
  SE3Quat T_cw;
};

struct DirectPoint {
  Eigen::Vector3d Pw = Eigen::Vector3d::Zero();
  PatchVector patch = PatchVector::Zero();
};

struct DirectBaProblem {
  std::vector<DirectPose> poses;
  std::vector<DirectPoint> points;
  std::vector<std::shared_ptr<const GrayImage>> images;          // one per pose
  double fx = 277.34, fy = 291.402, cx = 312.234, cy = 239.777;  // the exercise's camera
};

// Throw Error "<path>:<line>: <problem>".
std::vector<DirectPose> readDirectPoses(const std::string& path);
std::vector<DirectPoint> readDirectPoints(const std::string& path);
void writeDirectPoses(std::ostream& out, const std::vector<DirectPose>& poses);

struct DirectBaIteration {
  int iteration = 0;  // over all rounds
  double cost = 0;    // 1/2 sum rho(|e|^2) over the active edges
  size_t active_edges = 0;
  double time_s = 0;  // since the solve began
};

struct DirectBaOptions {
  double huber_delta = 5.128;  // sqrt(chi2 95% of 16 dof); the exercise uses 1
  int iterations = 100;        // LM iterations over all rounds
  // LM iterations between re-evaluations of the active set; 0 keeps the set of the start.
  int iterations_per_round = 10;
  bool fix_first_pose = true;
  // Patch pixels that count, as a centred n x n window of the 4x4 patch (n = 2, 3 or 4): the
  // other residuals get zero information. For the exercise's "which patch size" question.
  int patch_size = 4;
  // Points as inverse depth (a, b, rho) relative to camera 0 (held fixed) instead of world xyz:
  // the same problem, another parameterisation (docs/direct_ba.md compares them).
  bool inverse_depth = false;
  // Threads for the edges' errors and Jacobians (native LM; results are bit-identical for any
  // count, since accumulation stays serial). Ceres's threaded Schur was tried and dropped:
  // with its own step control, points whose patches clamp at the border ran off by kilometres.
  int threads = 1;
  std::function<void(const DirectBaIteration&)> progress;
  std::string validate() const;
};

struct PoseChange {
  double rotation_deg = 0, translation_m = 0;  // camera rotation and centre displacement
};

struct DirectBaSummary {
  size_t edges = 0;
  size_t active_edges_initial = 0, active_edges_final = 0;
  double initial_cost = 0, final_cost = 0;  // 1/2 sum rho(|e|^2), active edges
  int iterations = 0, rounds = 0;
  double time_s = 0;
  double max_point_motion_m = 0;
  std::vector<PoseChange> pose_change;
};

// Costs and the active set at the problem's current values, without solving.
struct DirectBaEvaluation {
  size_t edges = 0, active_edges = 0;
  double robust_cost = 0;        // 1/2 sum rho
  double plain_cost = 0;         // 1/2 sum |e|^2
  double mean_abs_residual = 0;  // per pixel, active edges
};
DirectBaEvaluation evaluateDirectBa(const DirectBaProblem& problem, double huber_delta);

// Refines problem.poses and problem.points in place.
DirectBaSummary solveDirectBa(DirectBaProblem& problem, const DirectBaOptions& options);

}  // namespace pnpba
