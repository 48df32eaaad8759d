// Graph bookkeeping, validation, back-end choice and the g2o-style log of SparseOptimizer.
// The back ends live in native_levenberg.cpp and sparse_optimizer_ceres.cpp.
#include "pnpba/optimize/sparse_optimizer.h"

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <iostream>

#include "native_levenberg.h"
#include "pnpba/core/error.h"

namespace pnpba {

namespace {
std::string edgeName(const Edge* e) { return "edge " + std::to_string(e->id()); }

// The first of the id-ordered vertices whose id is not below `id`.
std::vector<std::unique_ptr<Vertex>>::const_iterator lowerBound(
    const std::vector<std::unique_ptr<Vertex>>& vertices, int id) {
  return std::lower_bound(vertices.begin(), vertices.end(), id,
                          [](const std::unique_ptr<Vertex>& v, int i) { return v->id() < i; });
}
}  // namespace

const char* toString(SolverBackend backend) {
  switch (backend) {
    case SolverBackend::kAuto:
      return "auto";
    case SolverBackend::kNative:
      return "native";
    case SolverBackend::kCeres:
      return "ceres";
  }
  return "?";
}

SolverBackend parseSolverBackend(const std::string& name) {
  if (name == "auto") return SolverBackend::kAuto;
  if (name == "native") return SolverBackend::kNative;
  if (name == "ceres") return SolverBackend::kCeres;
  throw Error("unknown solver '" + name + "' (expected auto, native or ceres)");
}

const char* toString(LinearSolver solver) {
  switch (solver) {
    case LinearSolver::kAuto:
      return "auto";
    case LinearSolver::kDenseSchur:
      return "dense_schur";
    case LinearSolver::kSparseSchur:
      return "sparse_schur";
    case LinearSolver::kIterativeSchur:
      return "iterative_schur";
  }
  return "?";
}

LinearSolver parseLinearSolver(const std::string& name) {
  for (LinearSolver s : {LinearSolver::kAuto, LinearSolver::kDenseSchur, LinearSolver::kSparseSchur,
                         LinearSolver::kIterativeSchur}) {
    if (name == toString(s)) return s;
  }
  throw Error("unknown linear solver '" + name +
              "' (expected auto, dense_schur, sparse_schur or iterative_schur)");
}

std::string OptimizerOptions::validate() const {
  if (!(tau > 0)) return "tau must be > 0";
  if (!(user_lambda_init >= 0)) return "user_lambda_init must be >= 0";
  if (!(min_relative_accepted_decrease >= 0)) return "min_relative_accepted_decrease must be >= 0";
  if (!(min_relative_predicted_decrease >= 0)) {
    return "min_relative_predicted_decrease must be >= 0";
  }
  if (max_trials_after_failure < 1) return "max_trials_after_failure must be >= 1";
  if (auto_native_max_reduced_dim < 0) return "auto_native_max_reduced_dim must be >= 0";
  if (!(function_tolerance >= 0)) return "function_tolerance must be >= 0";
  if (!(gradient_tolerance >= 0)) return "gradient_tolerance must be >= 0";
  if (!(parameter_tolerance >= 0)) return "parameter_tolerance must be >= 0";
  if (num_threads < 1) return "num_threads must be >= 1";
  return "";
}

SparseOptimizer::SparseOptimizer() = default;
SparseOptimizer::~SparseOptimizer() = default;

bool SparseOptimizer::addVertex(Vertex* v) {
  std::unique_ptr<Vertex> owned(v);
  if (!owned) throw Error("addVertex: null vertex");
  const int id = owned->id();
  if (owned->graph_ != nullptr) {
    owned.release();  // its owner keeps it
    throw Error("addVertex: vertex " + std::to_string(id) + " already belongs to an optimizer");
  }
  if (vertices_.empty() || vertices_.back()->id() < id) {
    vertices_.push_back(std::move(owned));
  } else {
    const auto at = lowerBound(vertices_, id);
    if ((*at)->id() == id) throw Error("addVertex: duplicate vertex id " + std::to_string(id));
    vertices_.insert(at, std::move(owned));
  }
  v->graph_ = this;
  initialized_ = false;
  return true;
}

bool SparseOptimizer::addEdge(Edge* e) {
  std::unique_ptr<Edge> owned(e);
  if (!owned) throw Error("addEdge: null edge");
  for (size_t i = 0; i < owned->numVertices(); ++i) {
    Vertex* v = owned->vertex(i);
    if (v == nullptr) {
      throw Error(edgeName(e) + ": vertex " + std::to_string(i) +
                  " is not set (was optimizer.vertex(id) null?)");
    }
    if (v->graph() != this) {
      throw Error(edgeName(e) + ": vertex " + std::to_string(i) + " (id " +
                  std::to_string(v->id()) + ") is not in this optimizer");
    }
  }
  edge_list_.push_back(owned.get());
  edges_.push_back(std::move(owned));
  initialized_ = false;
  return true;
}

bool SparseOptimizer::addParameter(Parameter* p) {
  std::unique_ptr<Parameter> owned(p);
  if (!owned) throw Error("addParameter: null parameter");
  if (parameters_.count(owned->id()) != 0) {
    throw Error("addParameter: duplicate parameter id " + std::to_string(owned->id()));
  }
  parameters_.emplace(owned->id(), std::move(owned));
  return true;
}

Vertex* SparseOptimizer::vertex(int id) const {
  const auto it = lowerBound(vertices_, id);
  return it == vertices_.end() || (*it)->id() != id ? nullptr : it->get();
}

Parameter* SparseOptimizer::parameter(int id) const {
  auto it = parameters_.find(id);
  return it == parameters_.end() ? nullptr : it->second.get();
}

void SparseOptimizer::clear() {
  active_edges_.clear();
  active_vertices_.clear();
  edge_list_.clear();
  edges_.clear();
  vertices_.clear();
  parameters_.clear();
  initialized_ = false;
}

bool SparseOptimizer::initializeOptimization(int level) {
  active_edges_.clear();
  active_vertices_.clear();
  initialized_ = false;
  // The vertices the active edges reach, in id order: marked through their Hessian index (free
  // until buildStructure), then collected by one pass over the id-ordered vertices.
  constexpr int kReached = -2;
  for (const std::unique_ptr<Vertex>& v : vertices_) v->setHessianIndex(-1);
  for (Edge* e : edge_list_) {
    if (e->level() != level) continue;
    for (size_t i = 0; i < e->numParameters(); ++i) {
      Parameter* p = parameter(e->parameterId(static_cast<int>(i)));
      if (p == nullptr) {
        throw Error(edgeName(e) + ": parameter " + std::to_string(e->parameterId(i)) +
                    " was not added to the optimizer");
      }
      e->resolveParameter(static_cast<int>(i), p);
    }
    active_edges_.push_back(e);
    for (size_t i = 0; i < e->numVertices(); ++i) e->vertex(i)->setHessianIndex(kReached);
  }
  for (const std::unique_ptr<Vertex>& v : vertices_) {
    if (v->hessianIndex() != kReached) continue;
    v->setHessianIndex(-1);
    active_vertices_.push_back(v.get());
  }
  validateActiveGraph();
  initialized_ = true;
  return true;
}

void SparseOptimizer::validateActiveGraph() const {
  for (const Edge* e : active_edges_) {
    if (!e->measurementIsFinite()) {
      throw Error(edgeName(e) + ": measurement or information is not finite (NaN/Inf)");
    }
  }
  for (const Vertex* v : active_vertices_) {
    if (!v->estimateIsFinite()) {
      throw Error("vertex " + std::to_string(v->id()) + ": estimate is not finite (NaN/Inf)");
    }
  }
}

void SparseOptimizer::computeActiveErrors() {
  for (Edge* e : active_edges_) e->computeError();
}

double SparseOptimizer::activeChi2() const {
  double chi2 = 0;
  for (const Edge* e : active_edges_) chi2 += e->chi2();
  return chi2;
}

double SparseOptimizer::activeRobustChi2() const {
  double chi2 = 0;
  for (const Edge* e : active_edges_) chi2 += e->robustChi2();
  return chi2;
}

bool SparseOptimizer::computeMarginalCovariance(int vertex_id, Eigen::MatrixXd* covariance) {
  if (!initialized_)
    throw Error("computeMarginalCovariance() called before initializeOptimization()");
  Vertex* v = vertex(vertex_id);
  if (v == nullptr)
    throw Error("computeMarginalCovariance: no vertex " + std::to_string(vertex_id));
  if (v->fixed() || v->marginalized()) {
    throw Error("computeMarginalCovariance: vertex " + std::to_string(vertex_id) +
                " is fixed or marginalized");
  }
  if (!native_) native_ = std::make_unique<NativeLevenberg>();
  native_->useTwoViewKernel(options_.two_view_kernel);
  native_->buildStructure(active_vertices_, active_edges_);
  if (v->hessianIndex() < 0) return false;  // no active edge reaches it
  Eigen::MatrixXd full;
  if (!native_->reducedCovariance(&full)) return false;
  const int o = native_->poseOffset(v->hessianIndex()), d = native_->poseDim(v->hessianIndex());
  *covariance = full.block(o, o, d, d);
  return true;
}

SolverBackend SparseOptimizer::chooseBackend() const {
  if (options_.backend != SolverBackend::kAuto) return options_.backend;
  int reduced_dims = 0;
  for (const Vertex* v : active_vertices_) {
    if (!v->fixed() && !v->marginalized()) reduced_dims += v->dimension();
  }
  return reduced_dims <= options_.auto_native_max_reduced_dim ? SolverBackend::kNative
                                                              : SolverBackend::kCeres;
}

void SparseOptimizer::report(const IterationStats& s) const {
  if (callback_) callback_(s);
  if (!verbose_) return;
  std::ostream& os = log_stream_ != nullptr ? *log_stream_ : std::cerr;
  const auto flags = os.flags();
  os << "iteration= " << s.iteration << "\t chi2= " << std::fixed << s.chi2;
  os.flags(flags);
  os << "\t time= " << s.time_s << "\t cumTime= " << s.cum_time_s << "\t edges= " << s.edges
     << "\t schur= 1\t lambda= " << std::fixed << s.lambda;
  os.flags(flags);
  os << "\t levenbergIter= " << s.levenberg_trials << "\n";
}

int SparseOptimizer::optimize(int iterations) {
  if (!initialized_) throw Error("optimize() called before initializeOptimization()");
  const std::string problem = options_.validate();
  if (!problem.empty()) throw Error("optimizer options: " + problem);
  validateActiveGraph();
  summary_ = OptimizationSummary{};
  summary_.backend = chooseBackend();
  // The native solve's time (summary_.time_s) includes laying out its system and the first pass.
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const bool native =
      summary_.backend == SolverBackend::kNative && iterations > 0 && !active_edges_.empty();
  if (native) {
    // The native solver starts from the errors (and, where its edges give both, the
    // linearisation) at the current estimates in one pass, summed in edge order as below.
    if (!native_) native_ = std::make_unique<NativeLevenberg>();
    native_->useTwoViewKernel(options_.two_view_kernel);
    native_->buildStructure(active_vertices_, active_edges_);
    summary_.two_view_kernel = native_->runsTwoViewKernel();
    summary_.initial_chi2 = native_->evaluateAtCurrentEstimates();
  } else {
    computeActiveErrors();
    summary_.initial_chi2 = activeRobustChi2();
  }
  summary_.final_chi2 = summary_.initial_chi2;
  if (iterations <= 0 || active_edges_.empty()) {
    summary_.termination = "nothing to do";
    return 0;
  }
  if (summary_.backend == SolverBackend::kCeres) return optimizeCeres(iterations);

  native_->setConvergenceThreshold(options_.min_relative_predicted_decrease * summary_.initial_chi2,
                                   options_.min_relative_accepted_decrease * summary_.initial_chi2);
  int done = 0;
  summary_.termination = "iteration limit";
  double cum = 0;
  for (int i = 0; i < iterations; ++i) {
    const auto t0 = Clock::now();
    const auto result = native_->iterate(i == 0, options_);
    ++done;
    const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
    cum += dt;
    if (verbose_ || callback_) {
      if (!native_->errorsCurrent()) computeActiveErrors();
      report({i, activeRobustChi2(), dt, cum, active_edges_.size(), native_->lambda(),
              native_->trials()});
    }
    if (result == NativeLevenberg::StepResult::kConverged) {
      summary_.termination = "converged: decrease below threshold";
      break;
    }
    if (result == NativeLevenberg::StepResult::kTerminate) {
      summary_.termination = "no step improves";
      break;
    }
  }
  if (!native_->errorsCurrent()) computeActiveErrors();
  summary_.iterations = done;
  summary_.final_chi2 = activeRobustChi2();
  summary_.time_s = std::chrono::duration<double>(Clock::now() - start).count();
  return done;
}

}  // namespace pnpba
