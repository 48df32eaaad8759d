// bundle_adjust_bal: bundle adjustment of a "Bundle Adjustment in the Large" problem (BAL text
// format, 9-parameter cameras), points eliminated by the Schur complement.
//
//   bundle_adjust_bal INPUT.txt [--output OUT.txt] [--initial-ply A.ply] [--final-ply B.ply]
//       [--json R.json] [--solver pnpba|ceres-dense_schur|ceres-sparse_schur|
//       ceres-iterative_schur|native] [--linear-solver auto|dense|sparse|cg]
//       [--iterations N] [--threads N] [--robust none|huber|cauchy] [--normalize]
//       [--rotation-sigma S] [--translation-sigma S] [--point-sigma S] [--seed N] [--verbose]
//
// Exit codes: 0 solved; 1 the solver failed; 2 usage or input error.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>

#include "pnpba/bal/bal_problem.h"
#include "pnpba/bal/bal_solver.h"
#include "pnpba/core/error.h"
#include "pnpba/core/output_file.h"
#include "tool_entry.h"

namespace {

constexpr const char* kProgram = "bundle_adjust_bal";

void writePly(const std::string& path, const pnpba::BalProblem& p) {
  pnpba::writeOutputFile(path, [&p](std::ostream& out) { pnpba::writeBalPly(out, p, true); });
}

}  // namespace

PNPBA_TOOL_MAIN(int argc, char** argv) {
  CLI::App app{"Bundle adjustment of a BAL problem (cameras r t f k1 k2, points marginalised)."};
  std::string input, output, initial_ply, final_ply, json_path;
  bool normalize = false, verbose = false;
  pnpba::BalSolveOptions options;
  pnpba::BalPerturbation perturbation;
  app.add_option("input", input, "BAL problem file")->required();
  app.add_option("--output", output, "write the solved problem in BAL format");
  app.add_option("--initial-ply", initial_ply, "PLY of cameras and points before solving");
  app.add_option("--final-ply", final_ply, "PLY of cameras and points after solving");
  app.add_option("--json", json_path, "write the summary as JSON");
  app.add_option("--solver", options.solver,
                 "pnpba (the dedicated solver), ceres-dense_schur, ceres-sparse_schur, "
                 "ceres-iterative_schur (Ceres, for comparison) or native (the graph engine)")
      ->capture_default_str();
  app.add_option("--linear-solver", options.linear_solver,
                 "pnpba's reduced camera system: auto (by size), dense, sparse or cg")
      ->capture_default_str();
  app.add_option("--iterations", options.iterations, "maximum LM iterations")
      ->capture_default_str();
  app.add_option("--threads", options.threads, "threads for Jacobians and Schur")
      ->capture_default_str();
  app.add_option("--robust", options.robust, "loss on each residual: none, huber, cauchy (1 px)")
      ->capture_default_str();
  app.add_flag("--single-precision", options.single_precision,
               "pnpba solver: factor the reduced camera system in float");
  app.add_flag("--normalize", normalize, "centre and scale the scene (Ceres bundle_adjuster's)");
  app.add_option("--rotation-sigma", perturbation.rotation_sigma,
                 "perturb angle-axis components (rad)");
  app.add_option("--translation-sigma", perturbation.translation_sigma, "perturb camera centres");
  app.add_option("--point-sigma", perturbation.point_sigma, "perturb points");
  app.add_option("--seed", perturbation.seed, "perturbation seed")->capture_default_str();
  app.add_option("--function-tolerance", options.function_tolerance)->capture_default_str();
  app.add_option("--gradient-tolerance", options.gradient_tolerance)->capture_default_str();
  app.add_option("--parameter-tolerance", options.parameter_tolerance)->capture_default_str();
  app.add_flag("--verbose", verbose,
               "per-iteration table (also without --verbose for runs "
               "longer than a moment)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    for (double s :
         {perturbation.rotation_sigma, perturbation.translation_sigma, perturbation.point_sigma}) {
      if (!(s >= 0) || !std::isfinite(s)) throw pnpba::Error("perturbation sigmas must be >= 0");
    }
    const std::string invalid = options.validate();
    if (!invalid.empty()) throw pnpba::Error("--" + invalid);

    for (const std::string& out : {output, initial_ply, final_ply, json_path}) {
      if (!out.empty()) pnpba::checkOutputPath(out);
    }
    // An output on standard output owns it; the human text goes to stderr.
    FILE* const text =
        pnpba::anyIsStandardOutput({output, initial_ply, final_ply, json_path}) ? stderr : stdout;
    pnpba::BalProblem problem = pnpba::readBal(input);
    if (normalize) pnpba::normalizeBal(problem);
    pnpba::perturbBal(problem, perturbation);
    if (!initial_ply.empty()) writePly(initial_ply, problem);
    std::fprintf(text, "%s: %d cameras, %d points, %zu observations\n", input.c_str(),
                 problem.num_cameras, problem.num_points, problem.observations.size());
    std::fprintf(text, "%4s %14s %12s %12s %12s %10s\n", "iter", "cost", "gradient", "step",
                 "lambda", "time_s");
    const pnpba::BalSolveSummary s =
        pnpba::solveBal(problem, options, [text](const pnpba::BalIteration& it) {
          if (it.iteration == 0) {
            std::fprintf(text, "%4d %14.6e %12s %12s %12s %10.3f\n", 0, it.cost, "-", "-", "-",
                         0.0);
          } else {
            std::fprintf(text, "%4d %14.6e %12.3e %12.3e %12.3e %10.3f\n", it.iteration, it.cost,
                         it.gradient_norm, it.step_norm, it.lambda, it.cum_time_s);
          }
          std::fflush(text);
        });
    std::fprintf(text, "\nsolver: %s%s%s, %d threads, %d iterations, %s\n", s.solver.c_str(),
                 s.linear_solver.empty() ? "" : " / ", s.linear_solver.c_str(), s.threads,
                 s.iterations, s.termination.c_str());
    std::fprintf(text, "cost (1/2 sum |r|^2): %.6e -> %.6e\n", s.initial_cost, s.final_cost);
    std::fprintf(text, "RMS reprojection error: %.4f px -> %.4f px\n", s.rms_px_initial,
                 s.rms_px_final);
    std::fprintf(text, "time: %.3f s (set-up included); peak memory %.0f MB\n", s.time_s,
                 s.peak_memory_mb);

    if (!output.empty()) {
      pnpba::writeOutputFile(output,
                             [&problem](std::ostream& out) { pnpba::writeBal(out, problem); });
    }
    if (!final_ply.empty()) writePly(final_ply, problem);
    if (!json_path.empty()) {
      const std::string text = pnpba::balSummaryJson(s);
      pnpba::writeOutputFile(json_path, [&text](std::ostream& out) { out << text; });
    }
    if (!s.ok) {
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
