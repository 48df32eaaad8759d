#include "pnpba/bal/bal_solver.h"

#include <chrono>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "pnpba/core/error.h"
#include "schur_lm_solver.h"

namespace pnpba {

namespace {

const char kCeresPrefix[] = "ceres-";

// "ceres-dense_schur" -> "dense_schur" (the optimize module's name); "" for other solvers.
std::string ceresLinearSolverName(const std::string& solver) {
  return solver.rfind(kCeresPrefix, 0) == 0 ? solver.substr(sizeof kCeresPrefix - 1) : "";
}

// The process's peak resident memory (VmHWM), MB.
double peakMemoryMb() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return 0;
}

OptimizerOptions optimizerOptions(const BalSolveOptions& o) {
  OptimizerOptions options;
  options.num_threads = o.threads;
  options.function_tolerance = o.function_tolerance;
  options.gradient_tolerance = o.gradient_tolerance;
  options.parameter_tolerance = o.parameter_tolerance;
  if (o.solver == "native") {
    options.backend = SolverBackend::kNative;
  } else {
    options.backend = SolverBackend::kCeres;
    options.linear_solver = parseLinearSolver(ceresLinearSolverName(o.solver));
  }
  return options;
}

}  // namespace

std::string BalSolveOptions::validate() const {
  if (iterations < 1) return "iterations must be >= 1";
  if (threads < 1) return "threads must be >= 1";
  if (single_precision && solver != "pnpba") return "single precision needs the pnpba solver";
  if (robust != "none" && robust != "huber" && robust != "cauchy") {
    return "robust: unknown loss '" + robust + "' (none, huber, cauchy)";
  }
  if (solver == "pnpba") {
    if (linear_solver != "auto" && linear_solver != "dense" && linear_solver != "sparse" &&
        linear_solver != "cg") {
      return "linear solver: unknown '" + linear_solver + "' (auto, dense, sparse, cg)";
    }
    if (!(function_tolerance >= 0) || !(gradient_tolerance >= 0) || !(parameter_tolerance >= 0)) {
      return "tolerances must be >= 0";
    }
    return "";
  }
  if (solver != "native") {
    const std::string name = ceresLinearSolverName(solver);
    bool known = false;
    try {
      if (!name.empty()) parseLinearSolver(name), known = true;
    } catch (const Error&) {
    }
    if (!known) {
      return "solver: unknown '" + solver +
             "' (pnpba, ceres-dense_schur, ceres-sparse_schur, ceres-iterative_schur, native)";
    }
  }
  return optimizerOptions(*this).validate();
}

BalSolveSummary solveBal(BalProblem& problem, const BalSolveOptions& options,
                         const std::function<void(const BalIteration&)>& on_iteration) {
  const std::string invalid = options.validate();
  if (!invalid.empty()) throw Error(invalid);
  if (options.solver == "pnpba") {
    BalSolveSummary summary = bal_detail::solveWithSchurLm(problem, options, on_iteration);
    summary.peak_memory_mb = peakMemoryMb();
    return summary;
  }
  BalSolveSummary summary;
  summary.threads = options.threads;
  summary.solver = options.solver;
  summary.rms_px_initial = problem.rmsPixels();

  const auto start = std::chrono::steady_clock::now();
  SparseOptimizer optimizer;
  optimizer.options() = optimizerOptions(options);
  buildBalGraph(optimizer, problem, options.robust);
  optimizer.initializeOptimization();
  optimizer.computeActiveErrors();
  summary.initial_cost = 0.5 * optimizer.activeRobustChi2();
  summary.table.push_back({0, summary.initial_cost, NAN, NAN, NAN, 0.0});
  if (on_iteration) on_iteration(summary.table.back());
  optimizer.setIterationCallback([&](const IterationStats& s) {
    summary.table.push_back(
        {s.iteration + 1, 0.5 * s.chi2, s.gradient_norm, s.step_norm, s.lambda, s.cum_time_s});
    if (on_iteration) on_iteration(summary.table.back());
  });
  const int done = optimizer.optimize(options.iterations);
  summary.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  readBalGraph(optimizer, problem);
  summary.final_cost = 0.5 * optimizer.activeRobustChi2();
  summary.rms_px_final = problem.rmsPixels();
  const OptimizationSummary& s = optimizer.summary();
  summary.iterations = s.iterations;
  summary.termination = s.termination;
  summary.ok = done > 0 && std::isfinite(summary.final_cost);
  summary.peak_memory_mb = peakMemoryMb();
  return summary;
}

std::string balSummaryJson(const BalSolveSummary& s) {
  nlohmann::json table = nlohmann::json::array();
  for (const BalIteration& it : s.table) {
    table.push_back({{"iteration", it.iteration}, {"cost", it.cost}, {"time_s", it.cum_time_s}});
  }
  const nlohmann::json j = {{"ok", s.ok},
                            {"initial_cost", s.initial_cost},
                            {"final_cost", s.final_cost},
                            {"rms_px_initial", s.rms_px_initial},
                            {"rms_px_final", s.rms_px_final},
                            {"iterations", s.iterations},
                            {"termination", s.termination},
                            {"time_s", s.time_s},
                            {"solver", s.solver},
                            {"linear_solver", s.linear_solver},
                            {"single_precision", s.single_precision},
                            {"threads", s.threads},
                            {"peak_memory_mb", s.peak_memory_mb},
                            {"per_iteration", table}};
  return j.dump(2) + "\n";
}

}  // namespace pnpba
