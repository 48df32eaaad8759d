// bal_bench: problem-49-7776-pre (Ladybug) without perturbation, side by side in one process:
//   ceres_autodiff   Ceres's bundle_adjuster configuration built from the installed Ceres with
//                    a Snavely autodiff cost on angle-axis cameras (tests/support)
//   pnpba_*          bundle_adjust_bal's solve: g2o-style graph, analytic Jacobians, SE3
//                    camera manifold, through the optimize module's Ceres back end
// all with 2 threads, points eliminated first (user ordering), 50 LM iterations. Reports
// median over repetitions of: time to reach cost <= 1.3358e4 (0.1 % above the best known
// 1.33442e4), total time, time per iteration, final cost, peak memory (VmHWM, reset per run).
//
//   build/bench/bal_bench [repetitions=3]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>

#include "pnpba/bal/bal_problem.h"
#include "snavely_autodiff.h"

namespace {

constexpr double kTargetCost = 1.3358e4;

// Resets the process's peak resident size so each run reports its own (Linux clear_refs 5).
void resetPeakMemory() { std::ofstream("/proc/self/clear_refs") << "5"; }

double peakMemoryMb() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return 0;
}

struct Run {
  double to_target_s = -1, total_s = 0, per_iteration_ms = 0, final_cost = 0, peak_mb = 0;
  int iterations = 0;
};

Run runCeresAutodiff(const pnpba::BalProblem& original) {
  pnpba::BalProblem p = original;
  resetPeakMemory();
  const auto start = std::chrono::steady_clock::now();
  ceres::Problem problem;
  for (const pnpba::BalObservation& o : p.observations) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<pnpba::test::SnavelyResidual, 2, 9, 3>(
                                 new pnpba::test::SnavelyResidual(o.u, o.v)),
                             nullptr, &p.cameras[9 * o.camera], &p.points[3 * o.point]);
  }
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (int q = 0; q < p.num_points; ++q) ordering->AddElementToGroup(&p.points[3 * q], 0);
  for (int c = 0; c < p.num_cameras; ++c) ordering->AddElementToGroup(&p.cameras[9 * c], 1);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_SCHUR;
  options.linear_solver_ordering = ordering;
  options.max_num_iterations = 50;
  options.num_threads = 2;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  const double setup_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ceres::Solve(options, &problem, &summary);
  Run r;
  r.total_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.final_cost = summary.final_cost;
  r.iterations = static_cast<int>(summary.iterations.size()) - 1;
  r.per_iteration_ms = 1000.0 * summary.minimizer_time_in_seconds / std::max(1, r.iterations);
  for (const auto& it : summary.iterations) {
    if (it.cost <= kTargetCost) {
      r.to_target_s =
          setup_s + summary.preprocessor_time_in_seconds + it.cumulative_time_in_seconds;
      break;
    }
  }
  r.peak_mb = peakMemoryMb();
  return r;
}

Run runPnpba(const pnpba::BalProblem& original, pnpba::LinearSolver solver) {
  pnpba::BalProblem p = original;
  resetPeakMemory();
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  pnpba::SparseOptimizer optimizer;
  optimizer.setSolverBackend(pnpba::SolverBackend::kCeres);
  optimizer.options().num_threads = 2;
  optimizer.options().linear_solver = solver;
  optimizer.options().function_tolerance = 1e-6;  // Ceres's default, as the example
  optimizer.options().gradient_tolerance = 1e-10;
  optimizer.options().parameter_tolerance = 1e-8;
  pnpba::buildBalGraph(optimizer, p);
  optimizer.initializeOptimization();
  Run r;
  optimizer.setIterationCallback([&](const pnpba::IterationStats& s) {
    if (r.to_target_s < 0 && 0.5 * s.chi2 <= kTargetCost) r.to_target_s = elapsed();
  });
  r.iterations = optimizer.optimize(50);
  r.total_s = elapsed();
  r.final_cost = 0.5 * optimizer.chi2();
  r.per_iteration_ms = 1000.0 * optimizer.summary().time_s / std::max(1, r.iterations);
  r.peak_mb = peakMemoryMb();
  return r;
}

template <typename F>
Run medianOf(int repetitions, F f) {
  std::vector<Run> runs;
  for (int i = 0; i < repetitions; ++i) runs.push_back(f());
  auto med = [&](double Run::*field) {
    std::vector<double> v;
    for (const Run& r : runs) v.push_back(r.*field);
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  Run m = runs.front();
  m.to_target_s = med(&Run::to_target_s);
  m.total_s = med(&Run::total_s);
  m.per_iteration_ms = med(&Run::per_iteration_ms);
  m.peak_mb = med(&Run::peak_mb);
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  const int repetitions = argc > 1 ? std::atoi(argv[1]) : 3;
  pnpba::BalProblem problem =
      pnpba::readBal(std::string(PNPBA_SHARED_DATA) + "/bal/problem-49-7776-pre.txt");
  pnpba::normalizeBal(problem);  // as the example does; projections are unchanged
  std::printf("problem-49-7776-pre: initial cost %.6e, %d repetitions, medians\n", problem.cost(),
              repetitions);
  std::printf("%-22s %12s %10s %12s %6s %14s %9s\n", "run", "to_1.3358e4", "total_s",
              "ms/iteration", "iters", "final_cost", "peak_MB");
  auto print = [](const char* name, const Run& r) {
    std::printf("%-22s %12.3f %10.3f %12.2f %6d %14.6e %9.1f\n", name, r.to_target_s, r.total_s,
                r.per_iteration_ms, r.iterations, r.final_cost, r.peak_mb);
  };
  print("ceres_autodiff dense", medianOf(repetitions, [&] { return runCeresAutodiff(problem); }));
  print("pnpba dense_schur",
        medianOf(repetitions, [&] { return runPnpba(problem, pnpba::LinearSolver::kDenseSchur); }));
  print("pnpba sparse_schur", medianOf(repetitions, [&] {
          return runPnpba(problem, pnpba::LinearSolver::kSparseSchur);
        }));
  print("pnpba iterative_schur", medianOf(repetitions, [&] {
          return runPnpba(problem, pnpba::LinearSolver::kIterativeSchur);
        }));
  return 0;
}
