// bundle_adjust_bal: bundle adjustment of a "Bundle Adjustment in the Large" problem (BAL text
// format, 9-parameter cameras), points eliminated by the Schur complement.
//
//   bundle_adjust_bal INPUT.txt [--output OUT.txt] [--initial-ply A.ply] [--final-ply B.ply]
//       [--json R.json] [--solver dense_schur|sparse_schur|iterative_schur|native]
//       [--iterations N] [--threads N] [--robust none|huber|cauchy] [--normalize]
//       [--rotation-sigma S] [--translation-sigma S] [--point-sigma S] [--seed N] [--verbose]
//
// Exit codes: 0 solved; 1 the solver failed; 2 usage or input error.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "atomic_write.h"
#include "pnpba/core/error.h"
#include "pnpba/bal/bal_problem.h"

namespace {

constexpr const char* kProgram = "bundle_adjust_bal";

void writePly(const std::string& path, const pnpba::BalProblem& p) {
  pnpba::writeFileAtomically(path, [&p](std::ostream& out) { pnpba::writeBalPly(out, p, true); });
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Bundle adjustment of a BAL problem (cameras r t f k1 k2, points marginalised)."};
  std::string input, output, initial_ply, final_ply, json_path, solver = "dense_schur",
                                                                robust = "none";
  int iterations = 50, threads = 1;
  bool normalize = false, verbose = false;
  pnpba::BalPerturbation perturbation;
  double function_tolerance = 1e-6, gradient_tolerance = 1e-10, parameter_tolerance = 1e-8;
  app.add_option("input", input, "BAL problem file")->required();
  app.add_option("--output", output, "write the solved problem in BAL format");
  app.add_option("--initial-ply", initial_ply, "PLY of cameras and points before solving");
  app.add_option("--final-ply", final_ply, "PLY of cameras and points after solving");
  app.add_option("--json", json_path, "write the summary as JSON");
  app.add_option("--solver", solver, "dense_schur, sparse_schur, iterative_schur or native")
      ->capture_default_str();
  app.add_option("--iterations", iterations, "maximum LM iterations")->capture_default_str();
  app.add_option("--threads", threads, "threads for Jacobians and Schur")->capture_default_str();
  app.add_option("--robust", robust, "loss on each residual: none, huber, cauchy (1 px)")
      ->capture_default_str();
  app.add_flag("--normalize", normalize, "centre and scale the scene (Ceres bundle_adjuster's)");
  app.add_option("--rotation-sigma", perturbation.rotation_sigma,
                 "perturb angle-axis components (rad)");
  app.add_option("--translation-sigma", perturbation.translation_sigma, "perturb camera centres");
  app.add_option("--point-sigma", perturbation.point_sigma, "perturb points");
  app.add_option("--seed", perturbation.seed, "perturbation seed")->capture_default_str();
  app.add_option("--function-tolerance", function_tolerance)->capture_default_str();
  app.add_option("--gradient-tolerance", gradient_tolerance)->capture_default_str();
  app.add_option("--parameter-tolerance", parameter_tolerance)->capture_default_str();
  app.add_flag("--verbose", verbose,
               "per-iteration table (also without --verbose for runs "
               "longer than a moment)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    if (iterations < 1) throw pnpba::Error("--iterations must be >= 1");
    if (threads < 1) throw pnpba::Error("--threads must be >= 1");
    for (double s :
         {perturbation.rotation_sigma, perturbation.translation_sigma, perturbation.point_sigma}) {
      if (!(s >= 0) || !std::isfinite(s)) throw pnpba::Error("perturbation sigmas must be >= 0");
    }
    pnpba::OptimizerOptions options;
    options.num_threads = threads;
    options.function_tolerance = function_tolerance;
    options.gradient_tolerance = gradient_tolerance;
    options.parameter_tolerance = parameter_tolerance;
    if (solver == "native") {
      options.backend = pnpba::SolverBackend::kNative;
    } else {
      options.backend = pnpba::SolverBackend::kCeres;
      options.linear_solver = pnpba::parseLinearSolver(solver);
    }
    const std::string problem_text = options.validate();
    if (!problem_text.empty()) throw pnpba::Error(problem_text);

    pnpba::BalProblem problem = pnpba::readBal(input);
    if (normalize) pnpba::normalizeBal(problem);
    pnpba::perturbBal(problem, perturbation);
    if (!initial_ply.empty()) writePly(initial_ply, problem);
    std::printf("%s: %d cameras, %d points, %zu observations\n", input.c_str(), problem.num_cameras,
                problem.num_points, problem.observations.size());

    const auto start = std::chrono::steady_clock::now();
    pnpba::SparseOptimizer optimizer;
    optimizer.options() = options;
    pnpba::buildBalGraph(optimizer, problem, robust);
    optimizer.initializeOptimization();
    optimizer.computeActiveErrors();
    const double initial_cost = 0.5 * optimizer.activeRobustChi2();
    const double rms_initial = problem.rmsPixels();
    std::printf("%4s %14s %12s %12s %12s %10s\n", "iter", "cost", "gradient", "step", "lambda",
                "time_s");
    std::printf("%4d %14.6e %12s %12s %12s %10.3f\n", 0, initial_cost, "-", "-", "-", 0.0);
    optimizer.setIterationCallback([](const pnpba::IterationStats& s) {
      std::printf("%4d %14.6e %12.3e %12.3e %12.3e %10.3f\n", s.iteration + 1, 0.5 * s.chi2,
                  s.gradient_norm, s.step_norm, s.lambda, s.cum_time_s);
      std::fflush(stdout);
    });
    const int done = optimizer.optimize(iterations);
    const double time_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    pnpba::readBalGraph(optimizer, problem);
    const double final_cost = 0.5 * optimizer.activeRobustChi2();
    const double rms_final = problem.rmsPixels();
    const pnpba::OptimizationSummary& s = optimizer.summary();
    std::printf("\nsolver: %s%s, %d iterations, %s\n", pnpba::toString(s.backend),
                s.backend == pnpba::SolverBackend::kCeres
                    ? (std::string(" ") + pnpba::toString(options.linear_solver)).c_str()
                    : "",
                s.iterations, s.termination.c_str());
    std::printf("cost (1/2 sum |r|^2): %.6e -> %.6e\n", initial_cost, final_cost);
    std::printf("RMS reprojection error: %.4f px -> %.4f px\n", rms_initial, rms_final);
    std::printf("time: %.3f s (graph construction included)\n", time_s);

    if (!output.empty()) {
      pnpba::writeFileAtomically(output,
                                 [&problem](std::ostream& out) { pnpba::writeBal(out, problem); });
    }
    if (!final_ply.empty()) writePly(final_ply, problem);
    if (!json_path.empty()) {
      const nlohmann::json j = {{"initial_cost", initial_cost},
                                {"final_cost", final_cost},
                                {"rms_px_initial", rms_initial},
                                {"rms_px_final", rms_final},
                                {"iterations", s.iterations},
                                {"termination", s.termination},
                                {"time_s", time_s},
                                {"solver", solver}};
      pnpba::writeFileAtomically(json_path, [&j](std::ostream& out) { out << j.dump(2) << "\n"; });
    }
    if (done == 0 || !std::isfinite(final_cost)) {
      std::fprintf(stderr, "%s: %s: solver failed: %s\n", kProgram, input.c_str(),
                   s.termination.c_str());
      return 1;
    }
    return 0;
  } catch (const pnpba::Error& e) {
    std::cerr << kProgram << ": " << e.what() << "\n";
    return 2;
  }
}
