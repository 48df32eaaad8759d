#include "pnpba/bal/bal_solver.h"

#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>

#include "pnpba/core/error.h"

namespace pnpba {

namespace {

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
    options.linear_solver = parseLinearSolver(o.solver);
  }
  return options;
}

}  // namespace

std::string BalSolveOptions::validate() const {
  if (iterations < 1) return "iterations must be >= 1";
  if (threads < 1) return "threads must be >= 1";
  if (robust != "none" && robust != "huber" && robust != "cauchy") {
    return "robust: unknown loss '" + robust + "' (none, huber, cauchy)";
  }
  if (solver != "native") {
    try {
      parseLinearSolver(solver);
    } catch (const Error& e) {
      return std::string("solver: ") + e.what();
    }
  }
  return optimizerOptions(*this).validate();
}

BalSolveSummary solveBal(BalProblem& problem, const BalSolveOptions& options,
                         const std::function<void(const BalIteration&)>& on_iteration) {
  const std::string invalid = options.validate();
  if (!invalid.empty()) throw Error(invalid);
  BalSolveSummary summary;
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
                            {"per_iteration", table}};
  return j.dump(2) + "\n";
}

}  // namespace pnpba
