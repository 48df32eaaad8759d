// SparseOptimizer's Ceres back end: one parameter block per active vertex, one residual block
// per active edge, marginalised vertices in elimination group 0 for the Schur solvers.
#include <chrono>
#include <memory>

#include "ceres_bridge.h"
#include "pnpba/optimize/sparse_optimizer.h"

namespace pnpba {

namespace {

// Past this many non-marginalised dofs the dense Schur complement is replaced by a sparse one.
constexpr int kDenseSchurMaxReducedDim = 600;

class LogCallback : public ceres::IterationCallback {
 public:
  LogCallback(std::function<void(const IterationStats&)> report, size_t edges)
      : report_(std::move(report)), edges_(edges) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    if (s.iteration == 0) return ceres::SOLVER_CONTINUE;  // the initial evaluation
    cum_ += s.iteration_time_in_seconds;
    IterationStats stats{s.iteration - 1,
                         2.0 * s.cost,
                         s.iteration_time_in_seconds,
                         cum_,
                         edges_,
                         1.0 / s.trust_region_radius,
                         s.step_is_successful ? 1 : 0};
    stats.gradient_norm = s.gradient_max_norm;
    stats.step_norm = s.step_norm;
    report_(stats);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  std::function<void(const IterationStats&)> report_;
  size_t edges_;
  double cum_ = 0;
};

}  // namespace

int SparseOptimizer::optimizeCeres(int iterations) {
  const auto start = std::chrono::steady_clock::now();
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::TAKE_OWNERSHIP;
  problem_options.enable_fast_removal = false;
  ceres::Problem problem(problem_options);

  // Parameter blocks: a copy of each vertex's estimate, written back after the solve.
  std::vector<std::vector<double>> blocks(active_vertices_.size());
  std::map<const Vertex*, double*> block_of;
  for (size_t i = 0; i < active_vertices_.size(); ++i) {
    const Vertex* v = active_vertices_[i];
    blocks[i].resize(v->blockSize());
    v->getBlock(blocks[i].data());
    block_of[v] = blocks[i].data();
  }
  for (const Edge* e : active_edges_) {
    std::vector<double*> ptrs;
    for (size_t i = 0; i < e->numVertices(); ++i) ptrs.push_back(block_of.at(e->vertex(i)));
    ceres::LossFunction* loss =
        e->robustKernel() ? new internal::KernelLoss(e->robustKernel()) : nullptr;
    problem.AddResidualBlock(new internal::EdgeCostFunction(e), loss, ptrs);
  }
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  int reduced_dims = 0, eliminated = 0;
  for (size_t i = 0; i < active_vertices_.size(); ++i) {
    const Vertex* v = active_vertices_[i];
    double* x = blocks[i].data();
    if (v->blockSize() != v->dimension()) problem.SetManifold(x, new internal::VertexManifold(v));
    if (v->fixed()) problem.SetParameterBlockConstant(x);
    const bool eliminate = v->marginalized() && !v->fixed();
    ordering->AddElementToGroup(x, eliminate ? 0 : 1);
    if (eliminate) ++eliminated;
    if (!v->fixed() && !v->marginalized()) reduced_dims += v->dimension();
  }

  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.max_num_iterations = iterations;
  options.function_tolerance = options_.function_tolerance;
  options.gradient_tolerance = options_.gradient_tolerance;
  options.parameter_tolerance = options_.parameter_tolerance;
  options.num_threads = options_.num_threads;
  options.logging_type = ceres::SILENT;
  if (eliminated > 0 && reduced_dims > 0) {
    options.linear_solver_type =
        reduced_dims <= kDenseSchurMaxReducedDim ? ceres::DENSE_SCHUR : ceres::SPARSE_SCHUR;
    switch (options_.linear_solver) {
      case LinearSolver::kAuto:
        break;
      case LinearSolver::kDenseSchur:
        options.linear_solver_type = ceres::DENSE_SCHUR;
        break;
      case LinearSolver::kSparseSchur:
        options.linear_solver_type = ceres::SPARSE_SCHUR;
        break;
      case LinearSolver::kIterativeSchur:
        options.linear_solver_type = ceres::ITERATIVE_SCHUR;
        options.preconditioner_type = ceres::SCHUR_JACOBI;
        break;
    }
    options.linear_solver_ordering = ordering;
  } else {
    options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    if (reduced_dims + 3 * eliminated <= kDenseSchurMaxReducedDim) {
      options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
    }
  }
  std::unique_ptr<LogCallback> callback;
  if (verbose_ || callback_) {
    callback = std::make_unique<LogCallback>([this](const IterationStats& s) { report(s); },
                                             active_edges_.size());
    options.callbacks.push_back(callback.get());
  }

  ceres::Solver::Summary ceres_summary;
  ceres::Solve(options, &problem, &ceres_summary);

  for (size_t i = 0; i < active_vertices_.size(); ++i) {
    if (!active_vertices_[i]->fixed()) active_vertices_[i]->setBlock(blocks[i].data());
  }
  computeActiveErrors();
  summary_.iterations = static_cast<int>(ceres_summary.iterations.size()) - 1;
  summary_.final_chi2 = activeRobustChi2();
  summary_.termination = ceres_summary.message;
  summary_.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (ceres_summary.termination_type == ceres::FAILURE) return 0;
  return summary_.iterations;
}

}  // namespace pnpba
