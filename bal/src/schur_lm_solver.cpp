#include "schur_lm_solver.h"

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>

#include "reduced_camera_system.h"

namespace pnpba::bal_detail {

namespace {

// Ceres's trust-region defaults (Solver::Options): the LM damping is diag(J^T J) / radius.
constexpr double kInitialRadius = 1e4, kMaxRadius = 1e16, kMinRadius = 1e-32;
constexpr double kMinRelativeDecrease = 1e-3;
constexpr int kMaxSparseCameras = 20000;

Eigen::Map<Eigen::VectorXd> asVector(std::vector<double>& v) {
  return Eigen::Map<Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

}  // namespace

std::string autoLinearSolver(int num_cameras, double density) {
  // Crossovers measured with bench/bal_bench (docs/bal.md): dense Cholesky wins on small or
  // nearly full systems, sparse Cholesky on banded ones, conjugate gradients when even the
  // sparse factor grows too large.
  if (num_cameras <= 32 || (density >= 0.3 && num_cameras <= 1000)) return "dense";
  if (num_cameras <= kMaxSparseCameras) return "sparse";
  return "cg";
}

BalSolveSummary solveWithSchurLm(BalProblem& problem, const BalSolveOptions& options,
                                 const std::function<void(const BalIteration&)>& on_iteration) {
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&start] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  BalSolveSummary summary;
  summary.solver = options.solver;
  summary.threads = options.threads;
  summary.single_precision = options.single_precision;
  // Without a robust loss the cost is 1/2 sum |r|^2, the RMS's own sum: it is read from the
  // solver's costs instead of a further pass over every observation.
  const RobustLoss loss = parseRobustLoss(options.robust);
  const double observations = static_cast<double>(problem.observations.size());
  auto rmsPixels = [&](double cost) {
    return loss == RobustLoss::kNone && observations > 0 ? std::sqrt(2.0 * cost / observations)
                                                         : problem.rmsPixels();
  };

  const ObservationIndex index(problem);
  summary.linear_solver = options.linear_solver;
  if (summary.linear_solver == "auto") {
    summary.linear_solver =
        autoLinearSolver(problem.num_cameras, reducedSystemDensity(problem, index));
  }
  ReducedCameraSystem system(problem, index, parseLinearSolverKind(summary.linear_solver), loss,
                             options.threads, options.single_precision);
  std::vector<double>& cameras = problem.cameras;
  std::vector<double>& points = problem.points;
  std::vector<double> candidate_cameras(cameras.size()), candidate_points(points.size());

  double cost = system.cost(cameras.data(), points.data());
  double gradient_norm = system.linearize(cameras.data(), points.data());
  summary.initial_cost = cost;
  summary.rms_px_initial = rmsPixels(cost);
  summary.table.push_back({0, cost, gradient_norm, NAN, NAN, elapsed()});
  if (on_iteration) on_iteration(summary.table.back());

  double radius = kInitialRadius, decrease_factor = 2;
  summary.termination = "NO_CONVERGENCE: maximum number of iterations";
  bool stop = gradient_norm <= options.gradient_tolerance;
  if (stop) summary.termination = "CONVERGENCE: gradient tolerance";
  int iteration = 0;
  Eigen::VectorXd dc, dp;
  while (!stop && iteration < options.iterations) {
    ++iteration;
    const double lambda = 1 / radius;
    bool success = false;
    double step_norm = 0;
    if (system.solve(radius, &dc, &dp)) {
      const double model_change = system.modelCostChange();
      step_norm = std::sqrt(dc.squaredNorm() + dp.squaredNorm());
      asVector(candidate_cameras) = asVector(cameras) + dc;
      asVector(candidate_points) = asVector(points) + dp;
      const double candidate_cost = system.cost(candidate_cameras.data(), candidate_points.data());
      const double x_norm =
          std::sqrt(asVector(cameras).squaredNorm() + asVector(points).squaredNorm());
      // Ceres's order: parameter tolerance, function tolerance, then the step's quality.
      if (step_norm <= options.parameter_tolerance * (x_norm + options.parameter_tolerance)) {
        summary.termination = "CONVERGENCE: parameter tolerance";
        stop = true;
      } else if (std::abs(cost - candidate_cost) <= options.function_tolerance * cost) {
        summary.termination = "CONVERGENCE: function tolerance";
        stop = true;
      } else if (model_change > 0 && std::isfinite(candidate_cost)) {
        const double quality = (cost - candidate_cost) / model_change;
        success = quality > kMinRelativeDecrease;
        if (success) {
          cameras.swap(candidate_cameras), points.swap(candidate_points);
          cost = candidate_cost;
          radius = std::min(kMaxRadius,
                            radius / std::max(1.0 / 3.0, 1.0 - std::pow(2 * quality - 1, 3)));
          decrease_factor = 2;
          gradient_norm = system.linearize(cameras.data(), points.data());
          if (gradient_norm <= options.gradient_tolerance) {
            summary.termination = "CONVERGENCE: gradient tolerance";
            stop = true;
          }
        }
      }
    }
    if (!success && !stop) {
      radius /= decrease_factor;
      decrease_factor *= 2;
      if (radius < kMinRadius) {
        summary.termination = "FAILURE: trust region radius below its minimum";
        stop = true;
      }
    }
    summary.table.push_back({iteration, cost, gradient_norm, step_norm, lambda, elapsed()});
    if (on_iteration) on_iteration(summary.table.back());
  }
  summary.iterations = iteration;
  summary.final_cost = cost;
  summary.time_s = elapsed();
  summary.rms_px_final = rmsPixels(cost);
  summary.ok = iteration > 0 && std::isfinite(cost) && summary.termination.rfind("FAILURE", 0) != 0;
  return summary;
}

}  // namespace pnpba::bal_detail
