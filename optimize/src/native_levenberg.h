// The native back end (internal): g2o's Levenberg-Marquardt (OptimizationAlgorithmLevenberg)
// on the Schur-reduced normal equations (BlockSolver), for small graphs.
//
// Layout: free non-marginalised vertices ("poses") form a dense reduced matrix S; each free
// marginalised vertex ("landmark") has its own diagonal block and one block per adjacent pose.
// Each iteration linearises once, then tries up to max_trials dampings lambda:
//   S = Hpp + lambda I - sum_l Hpl (Hll + lambda I)^-1 Hlp,  S xp = bp - sum_l Hpl Dl bl,
//   xl = Dl (bl - Hlp xp);
// a step is accepted when it lowers the robust chi2, with lambda scaled by
// max(1/3, min(2/3, 1 - (2 rho - 1)^3)); otherwise lambda *= nu, nu *= 2. Where every edge's
// linearisation also gives its error, a trial is evaluated by linearising: an accepted step is
// then already linearised for the next iteration (the same steps, one pass fewer).
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <vector>

#include "landmark_elimination.h"
#include "lm_damping.h"
#include "pnpba/optimize/optimizable_graph.h"
#include "two_view_kernel.h"

namespace pnpba {

struct OptimizerOptions;

class NativeLevenberg {
 public:
  enum class StepResult { kOk, kTerminate, kConverged };

  // Whether buildStructure hands a two-view graph to the two-view kernel (two_view_kernel.h).
  void useTwoViewKernel(bool use) { use_two_view_ = use; }
  // True while the graph laid out last runs on the two-view kernel.
  bool runsTwoViewKernel() const { return two_view_; }
  // Lays out the system for the active graph. Throws Error on a structure it cannot eliminate.
  void buildStructure(const std::vector<Vertex*>& active_vertices,
                      const std::vector<Edge*>& active_edges);
  // One LM iteration (g2o's solve(iteration)); `first` initialises lambda and nu.
  StepResult iterate(bool first, const OptimizerOptions& options);

  // Iterations end with kConverged when the first trial's predicted decrease is below this.
  // ... or when an accepted step leaves less than min_actual_decrease of chi2 to gain
  // (internal::ConvergenceByDecrease). Called at the start of every solve.
  void setConvergenceThreshold(double min_predicted_decrease, double min_actual_decrease) {
    min_predicted_decrease_ = min_predicted_decrease;
    convergence_ = internal::ConvergenceByDecrease(min_actual_decrease);
  }
  // Inverse of the undamped reduced matrix S at the current estimates; false if singular.
  bool reducedCovariance(Eigen::MatrixXd* covariance);
  // Offset and size of a pose vertex in the reduced system (hessianIndex() order).
  int poseOffset(int index) const { return pose_offset_.at(index); }
  int poseDim(int index) const { return pose_dim_.at(index); }
  double lambda() const { return lambda_; }
  int trials() const { return trials_; }
  double chi2() const { return current_chi2_; }
  bool errorsCurrent() const { return errors_current_; }
  // Every edge's error at the current estimates (and its Jacobians, where the edges' own
  // linearisation gives both), for the first iteration; returns their robust chi2 summed in
  // edge order. After buildStructure.
  double evaluateAtCurrentEstimates() {
    current_chi2_ = activeRobustChi2(trial_linearizes_);
    errors_current_ = true;
    jacobians_current_ = trial_linearizes_;
    return current_chi2_;
  }

 private:
  // Offsets into hll_/dinv_ and bl_/xl_, and a range of adjacency_ (landmark_elimination.h).
  using Landmark = LandmarkBlocks;
  // A pose-landmark block: the pose's index into pose_offset_/pose_dim_, its offset into hpl_.
  using Adjacent = AdjacentBlock;

  // buildStructure's parts: free vertices ordered poses first (returns the landmarks), then
  // storage for the diagonal and the off-diagonal (pose-landmark, pose-pose) blocks.
  std::vector<Vertex*> orderVertices(const std::vector<Vertex*>& active_vertices);
  void allocateDiagonalBlocks(const std::vector<Vertex*>& landmark_vertices);
  void allocateOffDiagonalBlocks();
  // Computes every edge's error (and its Jacobians when `linearize`), returns the robust chi2.
  double activeRobustChi2(bool linearize = false);
  // How many threads forEachEdge uses: one below 256 edges.
  size_t edgeThreads() const;
  template <typename F>
  void forEachEdge(F f);
  void buildSystem();
  bool solveDamped(double lambda);
  bool finiteSteps() const;  // the last solve's xp and xl all finite
  double predictedReduction(double lambda) const;
  void applyUpdate();
  // Landmarks of any size; the 6-dof pose / 3-dof point case runs landmark_elimination.h's kernels.
  void eliminateLandmarks(double lambda);
  void backSubstitute();

  std::vector<Vertex*> vertices_;  // free vertices: poses first, then landmarks
  std::vector<Edge*> edges_;
  std::vector<int> pose_offset_, pose_dim_;
  int num_pose_dims_ = 0;
  bool all_pose6_landmark3_ = true;
  std::vector<Landmark> landmarks_;
  std::vector<Adjacent> adjacency_;
  struct PosePoseBlock {
    int row_pose = 0, col_pose = 0;  // indices into pose_offset_/pose_dim_
    size_t offset = 0;               // into hpp_off_
  };
  std::vector<size_t> pose_hdiag_;  // offset of each pose's diagonal block in hpp_diag_
  std::vector<PosePoseBlock> pose_pose_blocks_;

  std::vector<double> hpp_diag_, hpp_off_;
  Eigen::MatrixXd s_;
  Eigen::VectorXd bp_, rhs_, xp_;
  std::vector<double> hll_, dinv_, bl_, xl_, hpl_;
  Eigen::LLT<Eigen::MatrixXd> llt_;

  double lambda_ = 0, nu_ = 2, current_chi2_ = 0, min_predicted_decrease_ = 0;
  internal::ConvergenceByDecrease convergence_;
  // True while every edge's error is the one at the current estimates (after an accepted
  // step), so the next iteration need not recompute them.
  bool errors_current_ = false;
  // Every edge's linearizeOplus() leaves its error too (Edge::linearizationUpdatesError): a trial
  // step is evaluated by linearising, and an accepted one leaves the Jacobians current.
  bool trial_linearizes_ = false;
  bool jacobians_current_ = false;
  int trials_ = 0;
  int threads_ = 1;
  bool use_two_view_ = true, two_view_ = false;
  TwoViewKernel two_view_kernel_;
};

}  // namespace pnpba
