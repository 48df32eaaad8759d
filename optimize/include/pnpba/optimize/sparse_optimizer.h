// SparseOptimizer: the g2o graph workflow (addVertex, addParameter, addEdge,
// initializeOptimization, optimize, chi2) solved by one of two Levenberg-Marquardt back ends:
//
//   SolverBackend::kNative  g2o's LM loop (DESIGN.md section 4: lambda_0 = tau * max diag H,
//                           gain-ratio update, at most 10 trials) on the Schur-reduced system,
//                           dense Cholesky of the reduced camera matrix. Iteration for
//                           iteration what a g2o user sees; fastest on small graphs.
//   SolverBackend::kCeres   ceres::Solver, LEVENBERG_MARQUARDT, DENSE_/SPARSE_SCHUR with the
//                           marginalised vertices in elimination group 0, analytic Jacobians
//                           from the edges through each vertex's manifold. Scales to large
//                           graphs and threads.
//   SolverBackend::kAuto    (default) native while the reduced system is small, else Ceres;
//                           the threshold is OptimizerOptions::auto_native_max_reduced_dim.
//
// Ownership follows g2o: the optimiser owns every vertex, edge and parameter added to it, and an
// edge owns its robust kernel. Bad graphs (null or duplicate vertex, edge on a vertex missing
// from the graph, missing parameter, NaN/Inf measurement or estimate) throw pnpba::Error with a
// message naming the vertex or edge; nothing is left half-added.
//
// Costs follow g2o: chi2 = sum e^T Omega e, with no 1/2 (twice a Ceres cost).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <iosfwd>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pnpba/optimize/optimizable_graph.h"

namespace pnpba {

enum class SolverBackend { kAuto, kNative, kCeres };

// Linear solver of the Ceres back end. kAuto: DENSE_SCHUR up to 600 reduced dofs, else
// SPARSE_SCHUR (normal Cholesky when nothing is marginalised). kIterativeSchur uses the
// SCHUR_JACOBI preconditioner.
enum class LinearSolver { kAuto, kDenseSchur, kSparseSchur, kIterativeSchur };
const char* toString(LinearSolver solver);
LinearSolver parseLinearSolver(const std::string& name);  // "dense_schur", ...; throws Error

// "auto", "native", "ceres"; parseSolverBackend throws Error on anything else.
const char* toString(SolverBackend backend);
SolverBackend parseSolverBackend(const std::string& name);

struct OptimizerOptions {
  SolverBackend backend = SolverBackend::kAuto;
  // kAuto runs the native path while the non-marginalised free dimensions are at most this
  // (measured crossover, see docs/optimize.md "Solver back ends").
  int auto_native_max_reduced_dim = 120;

  // Levenberg-Marquardt, both back ends where they apply.
  double tau = 1e-5;                  // native: lambda_0 = tau * max diag(H) (g2o's default)
  double user_lambda_init = 0.0;      // native: > 0 overrides tau
  int max_trials_after_failure = 10;  // native: rejected steps before giving up (g2o: 10)
  // native: stop once the damped linear model predicts a chi2 decrease below this fraction of
  // the starting chi2, i.e. nothing representable is left to gain. g2o has no such test and
  // instead spends a last iteration of 10 rejected trials at the round-off floor; the chi2
  // sequence before that is identical. Set to 0 for g2o's exact iteration count.
  double min_relative_predicted_decrease = 1e-15;
  // native: stop after an accepted step that lowered chi2 by less than this fraction of the
  // starting chi2 (LM converges quadratically there: the next step changes nothing that
  // matters). Set both thresholds to 0 for g2o's exact iteration count.
  double min_relative_accepted_decrease = 1e-10;

  // Ceres stopping rules (Ceres's own names). Tight by default so that both back ends stop
  // at the same minimum; loosen for speed.
  double function_tolerance = 1e-14;
  double gradient_tolerance = 1e-16;
  double parameter_tolerance = 1e-14;
  // native: a graph of one free VertexSE3Expmap, fixed ones and points each seen once by the
  // free pose, through EdgeProjectXYZ2UV / EdgeSE3ProjectXYZ edges with an information w I and
  // no robust kernel (the textbook's two-view graphs) runs a kernel vectorised across points:
  // the same steps to round-off, 1.2-1.5x faster a solve (docs/optimize.md). false: the general
  // path.
  bool two_view_kernel = true;
  // Threads for evaluating edges (both back ends) and, in Ceres, for its Schur elimination.
  // The native back end stays bit-identical for any count: only per-edge work is threaded.
  int num_threads = 1;
  LinearSolver linear_solver = LinearSolver::kAuto;

  // Empty when valid, else the first bad field: "tau must be > 0".
  std::string validate() const;
};

// One line of the g2o-style log (and of the iteration callback).
struct IterationStats {
  int iteration = 0;
  double chi2 = 0;        // robust chi2 after the iteration
  double time_s = 0;      // of this iteration
  double cum_time_s = 0;  // since optimize() began
  size_t edges = 0;       // active edges
  double lambda = 0;      // LM damping after the iteration (Ceres: 1 / trust region radius)
  int levenberg_trials = 0;
  double gradient_norm = 0;  // max-norm of the gradient (Ceres back end; 0 otherwise)
  double step_norm = 0;      // norm of the step taken (Ceres back end; 0 otherwise)
};

struct OptimizationSummary {
  SolverBackend backend = SolverBackend::kNative;  // the one that ran
  int iterations = 0;
  double initial_chi2 = 0;  // robust
  double final_chi2 = 0;    // robust
  double time_s = 0;
  std::string termination;       // why it stopped, e.g. "no step improves"
  bool two_view_kernel = false;  // the native solve ran on the two-view kernel (above)
};

class NativeLevenberg;

class SparseOptimizer {
 public:
  SparseOptimizer();
  ~SparseOptimizer();
  SparseOptimizer(const SparseOptimizer&) = delete;
  SparseOptimizer& operator=(const SparseOptimizer&) = delete;

  // Take ownership. Return true; throw Error on nullptr, duplicate id, unset vertex, etc.
  bool addVertex(Vertex* v);
  bool addEdge(Edge* e);
  bool addParameter(Parameter* p);

  Vertex* vertex(int id) const;
  Parameter* parameter(int id) const;
  size_t numVertices() const { return vertices_.size(); }
  size_t numEdges() const { return edges_.size(); }
  const std::vector<Edge*>& edges() const { return edge_list_; }
  const std::vector<Edge*>& activeEdges() const { return active_edges_; }
  const std::vector<Vertex*>& activeVertices() const { return active_vertices_; }

  // Activates the edges of `level` and the vertices they touch; validates the graph.
  bool initializeOptimization(int level = 0);
  // Runs up to `iterations` LM iterations; returns the number done (g2o: 0 on failure).
  int optimize(int iterations);

  void computeActiveErrors();
  // Sum of e^T Omega e over the active edges, at the current estimates (g2o's activeChi2).
  double chi2() const { return activeChi2(); }
  double activeChi2() const;
  // The same with each edge's robust kernel applied.
  double activeRobustChi2() const;

  // g2o's verbose log: one line per iteration, "iteration= chi2= time= cumTime= edges=
  // schur= lambda= levenbergIter=", written to std::cerr unless another stream is given.
  void setVerbose(bool verbose) { verbose_ = verbose; }
  bool verbose() const { return verbose_; }
  void setLogStream(std::ostream* stream) { log_stream_ = stream; }
  void setIterationCallback(std::function<void(const IterationStats&)> callback) {
    callback_ = std::move(callback);
  }

  OptimizerOptions& options() { return options_; }
  const OptimizerOptions& options() const { return options_; }
  void setSolverBackend(SolverBackend backend) { options_.backend = backend; }
  const OptimizationSummary& summary() const { return summary_; }

  // Covariance of a free, non-marginalised vertex's update (6x6 for a pose, [omega; upsilon]
  // order: rad^2, m^2) from the Schur-reduced information J^T W J at the current estimates,
  // i.e. with the marginalised vertices eliminated. It is in the units the information matrices
  // state (e.g. 1 px pixel noise). False when that information is singular.
  bool computeMarginalCovariance(int vertex_id, Eigen::MatrixXd* covariance);

  // Deletes every vertex, edge and parameter.
  void clear();

 private:
  void validateActiveGraph() const;
  SolverBackend chooseBackend() const;
  void report(const IterationStats& stats) const;
  int optimizeCeres(int iterations);

  // Owned vertices in id order: ids usually arrive ascending, so adding one appends, and a
  // lookup is a binary search over contiguous pointers (a std::map spent a node allocation per
  // vertex, a fifth of building and freeing the textbook graph).
  std::vector<std::unique_ptr<Vertex>> vertices_;
  std::vector<std::unique_ptr<Edge>> edges_;
  std::vector<Edge*> edge_list_;
  std::map<int, std::unique_ptr<Parameter>> parameters_;
  std::vector<Edge*> active_edges_;
  std::vector<Vertex*> active_vertices_;
  bool initialized_ = false;

  bool verbose_ = false;
  std::ostream* log_stream_ = nullptr;
  std::function<void(const IterationStats&)> callback_;
  OptimizerOptions options_;
  OptimizationSummary summary_;
  std::unique_ptr<NativeLevenberg> native_;
};

}  // namespace pnpba
