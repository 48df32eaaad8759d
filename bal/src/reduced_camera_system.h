// One linearisation of a BAL problem and the reduced camera system of its damped normal
// equations, the points eliminated by the Schur complement:
//   S = U - W V^-1 W^T,  S dc = -g_c + W V^-1 g_p,  dp = V^-1 (-g_p - W^T dc)
// built directly from the per-observation Jacobians (no global Jacobian, no W stored), in
// parallel over cameras (each thread writes only its own row of blocks: no write conflicts,
// and results independent of the thread count). Solved densely (Cholesky), sparsely (Eigen's
// SimplicialLDLT on the block pattern, analysed once) or by conjugate gradients on the implicit
// S with a block-Jacobi preconditioner.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <string>
#include <vector>

#include "pnpba/bal/bal_problem.h"
#include "snavely_projection.h"

namespace pnpba::bal_detail {

using Matrix9 = Eigen::Matrix<double, 9, 9>;
using Vector9 = Eigen::Matrix<double, 9, 1>;

enum class LinearSolverKind { kDense, kSparse, kConjugateGradients };
LinearSolverKind parseLinearSolverKind(const std::string& name);  // dense, sparse, cg

// Observation indices grouped by camera and by point (CSR), computed once.
struct ObservationIndex {
  std::vector<int> camera_start, by_camera, point_start, by_point;
  std::vector<int>
      camera_by_point;  // the camera of each by_point entry: a point's cameras in a run
  std::vector<std::vector<int>> camera_partners;  // cameraPartners
  explicit ObservationIndex(const BalProblem& problem);
};

// Per camera a, the cameras b > a that share a point with it, in increasing order: the
// off-diagonal blocks of the reduced camera system's upper triangle. Works in at most max_bits
// of scratch (8 MB: one pass up to 8000 cameras).
std::vector<std::vector<int>> cameraPartners(const BalProblem& problem,
                                             const ObservationIndex& index,
                                             size_t max_bits = size_t{64} << 20);

// The fraction of the reduced camera system's blocks (upper triangle) that are not zero: camera
// pairs that share a point.
double reducedSystemDensity(const BalProblem& problem, const ObservationIndex& index);

enum class RobustLoss { kNone, kHuber, kCauchy };
RobustLoss parseRobustLoss(const std::string& name);

class ReducedCameraSystem {
 public:
  // single_precision: factor the reduced camera system in float (dense and sparse solvers);
  // everything else stays double.
  ReducedCameraSystem(const BalProblem& problem, const ObservationIndex& index,
                      LinearSolverKind kind, RobustLoss loss, int threads,
                      bool single_precision = false);
  ~ReducedCameraSystem();

  // 1/2 sum rho(|r|^2) at the given parameters (residuals only).
  double cost(const double* cameras, const double* points) const;
  // Residuals and Jacobians at the given parameters (robustly weighted), the gradient and the
  // diagonal blocks U, V. Returns the gradient's max-norm. The Jacobian's columns are scaled by
  // 1 / (1 + column norm), the scales fixed at the first call (Ceres's jacobi_scaling): focal
  // lengths and rotations differ by orders of magnitude, and unscaled the Schur complement loses
  // positive definiteness to round-off at small damping.
  double linearize(const double* cameras, const double* points);
  // Solves (J^T J + D/mu) [dc; dp] = -g in the scaled variables, D the clamped diagonal of the
  // scaled J^T J (Ceres's LM damping), and returns the step in the problem's own variables.
  // False when the damped system is not positive definite.
  bool solve(double mu, Eigen::VectorXd* dc, Eigen::VectorXd* dp);
  // The model's predicted decrease 1/2|r|^2 - 1/2|r + J d|^2 for the last solved step.
  double modelCostChange() const { return model_cost_change_; }
  int conjugateGradientIterations() const { return cg_iterations_; }

 private:
  struct SparseStorage;
  // The reduced system's block pattern, its storage and (sparse) its symbolic factorisation.
  void buildPattern();
  void dampPoints(double mu);
  // W_i V_q^-1 for observation i of point q (9 x 3): its share of the point's elimination.
  Eigen::Matrix<double, 9, 3> eliminationBlock(int observation) const;
  void buildReducedSystem(Eigen::VectorXd* rhs);
  bool solveDense(const Eigen::VectorXd& rhs, Eigen::VectorXd* dc);
  bool solveSparse(const Eigen::VectorXd& rhs, Eigen::VectorXd* dc);
  bool solveConjugateGradients(const Eigen::VectorXd& rhs, Eigen::VectorXd* dc);
  void multiplySchur(const Eigen::VectorXd& x, Eigen::VectorXd* y) const;
  // The points' step for the cameras' step dc; returns the model's predicted decrease.
  double backSubstitute(const Eigen::VectorXd& dc, Eigen::VectorXd* dp) const;
  Vector9 cameraRhs(int camera) const;

  bool single_precision_;
  Eigen::MatrixXf dense_float_;
  const BalProblem& problem_;
  const ObservationIndex& index_;
  LinearSolverKind kind_;
  RobustLoss loss_;
  int threads_;
  int nc_, np_;
  // Per observation, robustly weighted (the residuals live only in linearize): the camera's
  // Jacobian, most of the solver's memory. The point's is not kept: a point enters through the
  // camera frame, P = R X + t, so its Jacobian is the translation's times R (jp).
  std::vector<Matrix29> Jc_;
  // Per camera, what takes the translation's scaled Jacobian to the point's before the point's
  // own scaling: diag(1 / translation scale) R.
  std::vector<Eigen::Matrix3d> point_map_;
  Matrix23 jp(int observation) const;
  // Per camera: the block of J^T J, the gradient, the damped block. Per point: the gradient and
  // the inverse of the damped block (the block itself is formed from jp when damping).
  std::vector<Matrix9> U_, U_damped_;
  std::vector<Vector9> g_c_;
  std::vector<Eigen::Matrix3d> V_inverse_;
  std::vector<Eigen::Vector3d> g_p_;
  // Dense reduced system (upper blocks), or the sparse one.
  Eigen::MatrixXd dense_;
  std::unique_ptr<SparseStorage> sparse_;
  std::vector<Matrix9> preconditioner_;  // inverted diagonal blocks of S (cg)
  int cg_iterations_ = 0;
  // Jacobi scaling of the Jacobian's columns, per camera and per point (fixed at iteration 0).
  std::vector<Vector9> camera_scale_;
  std::vector<Eigen::Vector3d> point_scale_;
  double model_cost_change_ = 0;
};

}  // namespace pnpba::bal_detail
