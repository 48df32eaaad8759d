// bal_synthetic: writes a generated BAL problem with known ground truth (bal/bal_synthetic.h):
// cameras on a ring around a scene, points seen by K neighbouring cameras, pixel noise, and a
// perturbed start, so the solvers can be measured at sizes no public file here has.
//
//   bal_synthetic --cameras N --points M [--observations-per-point K] [--noise-px S]
//       [--seed S] [--rotation-sigma R] [--translation-sigma T] [--point-sigma P]
//       --output FILE [--ground-truth FILE]
//
// Exit codes: 0 written; 2 usage error or unwritable output.
#include "pnpba/bal/bal_synthetic.h"

#include <CLI/CLI.hpp>
#include <cstdio>

#include "pnpba/bal/bal_problem.h"
#include "pnpba/core/error.h"
#include "pnpba/core/output_file.h"
#include "tool_entry.h"

PNPBA_TOOL_MAIN(int argc, char** argv) {
  CLI::App app{"Generate a BAL problem with known ground truth."};
  pnpba::BalSyntheticOptions o;
  std::string output, truth_path;
  app.add_option("--cameras", o.cameras, "cameras on the ring")->capture_default_str();
  app.add_option("--points", o.points, "scene points")->capture_default_str();
  app.add_option("--observations-per-point", o.observations_per_point,
                 "track length: cameras that see each point")
      ->capture_default_str();
  app.add_option("--noise-px", o.noise_px, "Gaussian pixel noise")->capture_default_str();
  app.add_option("--seed", o.seed, "random seed (scene, noise)")->capture_default_str();
  app.add_option("--rotation-sigma", o.start.rotation_sigma, "start: angle-axis noise, rad")
      ->capture_default_str();
  app.add_option("--translation-sigma", o.start.translation_sigma, "start: camera centre noise")
      ->capture_default_str();
  app.add_option("--point-sigma", o.start.point_sigma, "start: point noise")->capture_default_str();
  app.add_option("--output", output, "the problem to solve (perturbed start)")->required();
  app.add_option("--ground-truth", truth_path, "the true cameras and points, same observations");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    o.start.seed = o.seed + 1;
    const std::string invalid = o.validate();
    if (!invalid.empty()) throw pnpba::Error(invalid);
    for (const std::string& path : {output, truth_path}) {
      if (!path.empty()) pnpba::checkOutputPath(path);
    }
    const pnpba::BalSyntheticProblem p = pnpba::generateBalProblem(o);
    pnpba::writeOutputFile(output, [&p](std::ostream& out) { pnpba::writeBal(out, p.start); });
    if (!truth_path.empty()) {
      pnpba::writeOutputFile(truth_path,
                             [&p](std::ostream& out) { pnpba::writeBal(out, p.truth); });
    }
    std::fprintf(pnpba::anyIsStandardOutput({output, truth_path}) ? stderr : stdout,
                 "%d cameras, %d points, %zu observations; cost at the truth %.6e, at the start "
                 "%.6e\n",
                 p.start.num_cameras, p.start.num_points, p.start.observations.size(),
                 p.truth.cost(), p.start.cost());
    return 0;
  } catch (const pnpba::Error& e) {
    std::fprintf(stderr, "bal_synthetic: %s\n", e.what());
    return 2;
  }
}
