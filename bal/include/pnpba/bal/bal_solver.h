// Solving a BAL problem: options with validation, the solve itself on the optimize graph
// engine (native LM or Ceres), and a summary with the per-iteration table BA users read.
// Costs are Ceres's: 1/2 sum |r|^2 (half a g2o chi2).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "pnpba/bal/bal_problem.h"

namespace pnpba {

struct BalSolveOptions {
  // pnpba: the dedicated Schur LM of this module (the default); ceres-dense_schur,
  // ceres-sparse_schur, ceres-iterative_schur: Ceres through the optimize graph engine, for
  // comparison; native: the graph engine's own LM, for parity.
  std::string solver = "pnpba";
  // pnpba only: auto (by problem size), dense, sparse or cg (conjugate gradients on the
  // implicit Schur complement, block-Jacobi preconditioned).
  std::string linear_solver = "auto";
  // pnpba with dense or sparse: factor the reduced camera system in single precision (half
  // the memory of the factor; the steps stay exact enough for LM, docs/bal.md).
  bool single_precision = false;
  std::string robust = "none";  // none, huber, cauchy (width 1 px)
  int iterations = 50;
  int threads = 1;
  double function_tolerance = 1e-6, gradient_tolerance = 1e-10, parameter_tolerance = 1e-8;
  std::string validate() const;  // empty when valid, else names the option
};

struct BalIteration {
  int iteration = 0;  // 1-based; row 0 of the table is the initial cost
  double cost = 0, gradient_norm = 0, step_norm = 0, lambda = 0, cum_time_s = 0;
};

struct BalSolveSummary {
  bool ok = false;  // false: no step taken or a non-finite final cost
  std::string solver, termination;
  std::string linear_solver;  // what the pnpba solver used ("" for the others)
  bool single_precision = false;
  int threads = 1;
  double peak_memory_mb = 0;  // the process's peak resident memory after the solve
  int iterations = 0;
  double initial_cost = 0, final_cost = 0, rms_px_initial = 0, rms_px_final = 0;
  double time_s = 0;  // graph construction included
  std::vector<BalIteration> table;
};

// Solves in place (the problem holds the result). Throws Error for invalid options.
BalSolveSummary solveBal(BalProblem& problem, const BalSolveOptions& options,
                         const std::function<void(const BalIteration&)>& on_iteration = {});

std::string balSummaryJson(const BalSolveSummary& summary);

}  // namespace pnpba
