// An independent BAL solve for tests and benchmarks: the Snavely camera model (DESIGN.md
// section 4) as a templated Ceres functor with automatic derivatives on the raw 9 parameters
// (angle-axis), solved by Ceres directly, as Ceres's own bundle_adjuster example sets it up.
#pragma once

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <memory>
#include <string>

#include "pnpba/bal/bal_problem.h"

namespace pnpba::test {

struct SnavelyResidual {
  SnavelyResidual(double u, double v) : u(u), v(v) {}
  template <typename T>
  bool operator()(const T* camera, const T* point, T* residual) const {
    T P[3];
    ceres::AngleAxisRotatePoint(camera, point, P);
    for (int i = 0; i < 3; ++i) P[i] += camera[3 + i];
    const T x = -P[0] / P[2], y = -P[1] / P[2];
    const T r2 = x * x + y * y;
    const T scale = camera[6] * (T(1.0) + r2 * (camera[7] + camera[8] * r2));
    residual[0] = scale * x - u;  // predicted - observed, as the example
    residual[1] = scale * y - v;
    return true;
  }
  double u, v;
};

struct AutodiffSolve {
  double initial_cost = 0, final_cost = 0, time_s = 0;
  int iterations = 0;
  std::vector<double> iteration_costs;  // accepted iterations
  std::vector<double> all_costs;        // every row of Ceres's table, iteration 0 first
};

// Solves `problem` in place with LM + the given Schur solver, points in elimination group 0.
inline AutodiffSolve solveWithCeresAutodiff(BalProblem& problem, int iterations, int threads,
                                            ceres::LinearSolverType solver = ceres::DENSE_SCHUR,
                                            double function_tolerance = 1e-6,
                                            const std::vector<int>& fixed_cameras = {},
                                            const std::string& loss = "none") {
  ceres::Problem ceres_problem;
  for (const BalObservation& o : problem.observations) {
    ceres::LossFunction* l = nullptr;
    if (loss == "huber") l = new ceres::HuberLoss(1.0);
    if (loss == "cauchy") l = new ceres::CauchyLoss(1.0);
    ceres_problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<SnavelyResidual, 2, 9, 3>(new SnavelyResidual(o.u, o.v)), l,
        &problem.cameras[9 * o.camera], &problem.points[3 * o.point]);
  }
  for (int c : fixed_cameras) ceres_problem.SetParameterBlockConstant(&problem.cameras[9 * c]);
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (int q = 0; q < problem.num_points; ++q)
    ordering->AddElementToGroup(&problem.points[3 * q], 0);
  for (int c = 0; c < problem.num_cameras; ++c) {
    ordering->AddElementToGroup(&problem.cameras[9 * c], 1);
  }
  ceres::Solver::Options options;
  options.linear_solver_type = solver;
  options.linear_solver_ordering = ordering;
  options.max_num_iterations = iterations;
  options.num_threads = threads;
  options.function_tolerance = function_tolerance;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &ceres_problem, &summary);
  AutodiffSolve s;
  s.initial_cost = summary.initial_cost;
  s.final_cost = summary.final_cost;
  s.time_s = summary.total_time_in_seconds;
  s.iterations = static_cast<int>(summary.iterations.size()) - 1;
  for (const auto& it : summary.iterations) {
    if (it.step_is_successful) s.iteration_costs.push_back(it.cost);
    s.all_costs.push_back(it.cost);
  }
  return s;
}

}  // namespace pnpba::test
