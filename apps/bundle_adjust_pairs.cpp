// bundle_adjust_pairs: two-view bundle adjustment of a 3D-2D pair file, the way the textbook
// program refines its PnP pose, with any of pnpba's graphs and either solver back end.
//
//   bundle_adjust_pairs PAIRS.txt [--mode rgbd] [--solver auto] [--verbose] [--json R.json]
//
// Without --init the start pose is the motion-only least-squares pose, solved from the
// identity (fine for the small motions of a two-view pair). Exit codes: 0 success, 1 the
// solve failed, 2 bad input.
#include <CLI/CLI.hpp>
#include <cmath>
#include <iomanip>
#include <iostream>

#include "cli_values.h"
#include "pnpba/core/error.h"
#include "pnpba/core/output_file.h"
#include "pnpba/pipeline/pairs_adjustment.h"
#include "pnpba/pipeline/pairs_file.h"
#include "tool_entry.h"

namespace {

constexpr const char* kProgram = "bundle_adjust_pairs";

}  // namespace

PNPBA_TOOL_MAIN(int argc, char** argv) {
  CLI::App app{
      "Two-view bundle adjustment of a 3D-2D pair file (X Y Z u2 v2 [u1 v1] per line): prints "
      "the refined T = T_21 (camera 2 from camera 1)."};
  std::string pairs_path, mode_name = "rgbd", solver_name = "auto", intrinsics_text, init_text,
                          json_path;
  int iterations = 100;
  bool verbose = false;
  pnpba::PoseGraphOptions graph;
  app.add_option("pairs", pairs_path, "pair file: X Y Z u2 v2 [u1 v1] per line")->required();
  app.add_option("--mode", mode_name,
                 "graph: pose, textbook, two-camera, rgbd (two-camera and rgbd need u1 v1)")
      ->capture_default_str();
  app.add_option("--solver", solver_name, "back end: auto, native (g2o's LM), ceres")
      ->capture_default_str();
  app.add_option("--intrinsics", intrinsics_text, "fx,fy,cx,cy (default: 520.9,521.0,325.1,249.7)");
  app.add_option("--init", init_text,
                 "start pose r00,r01,...,r22,tx,ty,tz (default: motion-only LS from identity)");
  app.add_option("--iterations", iterations, "maximum LM iterations")->capture_default_str();
  app.add_flag("--robust", graph.robust, "Huber kernels (width sqrt of the chi2 95% quantile)");
  app.add_option("--depth-noise", graph.depth_noise_k, "k in sigma_z = k z^2 (1/m), rgbd mode")
      ->capture_default_str();
  app.add_option("--json", json_path, "write the figures to this JSON file");
  app.add_flag("--verbose", verbose, "g2o-style per-iteration log");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }

  try {
    pnpba::PairsAdjustmentOptions options;
    options.graph = graph;
    options.graph.mode = pnpba::parseBundleMode(mode_name);
    options.backend = pnpba::parseSolverBackend(solver_name);
    options.iterations = iterations;
    // An output on standard output owns it; the human text goes to stderr.
    std::ostream& text = pnpba::anyIsStandardOutput({json_path}) ? std::cerr : std::cout;
    if (verbose) options.log = &text;
    if (!intrinsics_text.empty()) {
      const auto k = pnpba::parseNumberList(intrinsics_text, 4, "--intrinsics");
      options.graph.intrinsics = {k[0], k[1], k[2], k[3]};
    }
    if (!init_text.empty()) {
      const auto v = pnpba::parseNumberList(init_text, 12, "--init");
      Eigen::Matrix3d R;
      R << v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8];
      if (!(R * R.transpose()).isIdentity(1e-6) || R.determinant() < 0) {
        throw pnpba::Error("--init: R is not a rotation matrix");
      }
      options.start = pnpba::SE3Quat(R, Eigen::Vector3d(v[9], v[10], v[11]));
    }
    const std::string problem = options.validate();
    if (!problem.empty()) throw pnpba::Error("--" + problem);
    for (const std::string& out : {json_path}) {
      if (!out.empty()) pnpba::checkOutputPath(out);
    }
    const pnpba::PairsFile file = pnpba::readPairsFile(pairs_path);
    const bool needs_image1 = options.graph.mode == pnpba::BundleMode::kTwoCamera ||
                              options.graph.mode == pnpba::BundleMode::kRgbd;
    if (needs_image1 && !file.has_image1_pixels) {
      throw pnpba::Error(pairs_path + ": mode " + mode_name +
                         " needs image-1 pixels (7 columns: X Y Z u2 v2 u1 v1)");
    }

    if (file.pairs.size() < 6) {
      std::cerr << kProgram << ": " << pairs_path << ": " << file.pairs.size()
                << " pairs < 6 required\n";
      return 1;
    }
    options.start = pnpba::pairsStartPose(file.pairs, options);
    text << "pairs: " << file.pairs.size() << "\n";
    const Eigen::Matrix4d T0 = options.start->to_homogeneous_matrix();
    text << "initial R=\n" << T0.topLeftCorner<3, 3>() << "\n";
    text << "initial t=\n" << T0.topRightCorner<3, 1>().transpose() << "\n";
    text << "bundle adjustment (" << mode_name << " graph):\n";
    const pnpba::PairsAdjustment r = pnpba::adjustPairs(file.pairs, options);
    text << "solver: " << pnpba::toString(r.summary.backend) << ", " << r.summary.iterations
         << " iterations, " << r.summary.termination << "\n";
    text << std::setprecision(10) << "chi2: " << r.chi2_initial << " -> " << r.chi2_final << "\n"
         << std::setprecision(6);
    text << "optimization costs time: " << r.summary.time_s << " seconds.\n";
    text << "\nafter optimization:\nT=\n" << r.T_21.to_homogeneous_matrix() << "\n";
    if (!json_path.empty()) {
      const std::string text = pnpba::pairsAdjustmentJson(r, file.pairs.size(), mode_name);
      pnpba::writeOutputFile(json_path, [&text](std::ostream& out) { out << text; });
    }
    if (!r.ok) {
      std::cerr << kProgram << ": " << pairs_path << ": " << r.failure << "\n";
      return 1;
    }
    return 0;
  } catch (const pnpba::Error& e) {
    std::cerr << kProgram << ": " << e.what() << "\n";
    return 2;
  }
}
