// pnpba's own BAL solver: Levenberg-Marquardt with Ceres's trust-region schedule and stopping
// rules on the raw Snavely parameters (snavely_projection.h), the points eliminated by the Schur
// complement. Used by solveBal for the solver name "pnpba".
#pragma once

#include <functional>

#include "pnpba/bal/bal_problem.h"
#include "pnpba/bal/bal_solver.h"

namespace pnpba::bal_detail {

BalSolveSummary solveWithSchurLm(BalProblem& problem, const BalSolveOptions& options,
                                 const std::function<void(const BalIteration&)>& on_iteration);

// The linear solver "auto" picks for a problem with this many cameras and this share of
// non-zero blocks in its reduced camera system (measured crossovers, docs/bal.md).
std::string autoLinearSolver(int num_cameras, double density);

}  // namespace pnpba::bal_detail
