// evaluate_tum: every pair (i, i+k), 1 <= k <= K, of a TUM RGB-D sequence, estimated with each
// requested method and scored against the interpolated ground truth (relative pose error).
//
//   evaluate_tum DIR [--camera FILE] [--max-gap 8 | --gaps 1,3]
//                [--methods rgbd,pose,none,textbook,opencv[,open3d]]
//                [--json R.json] [--csv R.csv] [--plot R.png] [--trajectory OUT.txt]
//                [--gt-offset SECONDS]
//
// Exit codes: 0 evaluated (failed pairs are reported, not fatal); 2 usage or input error.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "covariance_cli.h"
#include "evaluation_plot.h"
#include "pnpba/core/error.h"
#include "pnpba/core/output_file.h"
#include "pnpba/evaluation/tum_cameras.h"
#include "pnpba/evaluation/tum_evaluation.h"
#include "tool_entry.h"

namespace {

constexpr const char* kProgram = "evaluate_tum";

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

// --ba replaces the BA modes of --methods; the baselines ("opencv", "open3d") stay if they were
// asked for.
std::vector<std::string> chooseMethods(const std::string& methods_text,
                                       const std::vector<std::string>& ba_modes) {
  std::vector<std::string> methods = splitList(methods_text);
  if (ba_modes.empty()) return methods;
  std::vector<std::string> chosen = ba_modes;
  for (const char* baseline : {"opencv", "open3d"}) {
    if (std::find(methods.begin(), methods.end(), baseline) != methods.end()) {
      chosen.push_back(baseline);
    }
  }
  return chosen;
}

std::vector<pnpba::PlotPair> plotPairs(const pnpba::TumEvaluation& ev) {
  std::vector<pnpba::PlotPair> pairs;
  for (const pnpba::PairRecord& r : ev.records) {
    if (pairs.empty() || pairs.back().i != r.i || pairs.back().j != r.j) {
      pairs.push_back({r.i, r.j, {}});
    }
    pairs.back().errors.push_back({r.ok, r.error, r.time_ms, false, {}});
  }
  return pairs;
}

void writeText(const std::string& path, const std::string& text) {
  pnpba::writeOutputFile(path, [&text](std::ostream& o) { o << text; });
}

}  // namespace

PNPBA_TOOL_MAIN(int argc, char** argv) {
  CLI::App app{"Evaluate two-view pose methods on a TUM RGB-D sequence against ground truth."};
  pnpba::TumEvaluationOptions options;
  std::string methods_text = "rgbd,pose,none,textbook,opencv", json_path, csv_path, plot_path,
              trajectory_path;
  std::vector<std::string> ba_modes;
  app.add_option("folder", options.folder,
                 "sequence folder (rgb/, depth/, associate.txt or rgb.txt + "
                 "depth.txt, groundtruth.txt), or a key-frame folder (rgb/NNNN.jpg, "
                 "depth/NNNN.png, poses.txt: 'frame stamp tx ty tz qx qy qz qw')")
      ->required();
  app.add_option("--camera", options.camera_path,
                 "camera YAML (default: FOLDER/camera.yaml, else the TUM freiburg1/2/3 camera "
                 "the folder's path names, e.g. rgbd_dataset_freiburg3_cabinet, else freiburg1)");
  app.add_option("--max-gap", options.max_gap, "evaluate pairs (i, i+k) for k = 1..K")
      ->capture_default_str();
  app.add_option("--gaps", options.gaps,
                 "evaluate only pairs (i, i+k) for these k, e.g. --gaps 1,3 (overrides --max-gap)")
      ->delimiter(',');
  app.add_option("--methods", methods_text,
                 "comma list: none, pose, textbook, two-camera, rgbd (BA modes), opencv (ORB + "
                 "solvePnPRansac), open3d (Open3D's RGB-D odometry, about 0.5 s a pair)")
      ->capture_default_str();
  app.add_option("--ba", ba_modes, "BA mode(s) to evaluate instead of --methods' BA modes");
  app.add_option("--features", options.features, "ORB features for every method")
      ->capture_default_str();
  app.add_option("--gt-offset", options.gt_offset_s,
                 "seconds added to image stamps before interpolating the ground truth "
                 "(TUM tools' convention; never chosen automatically)")
      ->capture_default_str();
  addCovarianceOptions(app, options.covariance);
  app.add_option("--json", json_path, "write per-method statistics and per-pair results");
  app.add_option("--csv", csv_path, "write one row per pair and method");
  app.add_option("--plot", plot_path, "write a PNG of the errors per pair and method");
  app.add_option("--trajectory", trajectory_path,
                 "chain the first method's consecutive estimates into a TUM trajectory");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }

  try {
    options.methods = chooseMethods(methods_text, ba_modes);
    const std::string problem = options.validate();
    if (!problem.empty()) throw pnpba::Error(problem);
    for (const std::string& out : {json_path, csv_path, plot_path, trajectory_path}) {
      if (!out.empty()) pnpba::checkOutputPath(out);
    }
    // An output on standard output owns it; the human text goes to stderr.
    std::ostream& text =
        pnpba::anyIsStandardOutput({json_path, csv_path, plot_path, trajectory_path}) ? std::cerr
                                                                                      : std::cout;
    // Which camera, before the pairs: a wrong guess costs accuracy quietly (tum_cameras.h).
    text << "camera: " << pnpba::sequenceCamera(options.folder, options.camera_path).source
         << std::endl;
    const pnpba::TumEvaluation ev = pnpba::evaluateTumSequence(
        options, [&text](const std::string& line) { text << line << std::endl; });
    text << "sequence " << ev.folder << ": " << ev.frames << " frames ("
         << ev.frames_without_ground_truth << " without ground truth skipped, "
         << ev.frames_missing_files << " listed but missing)\n";
    if (ev.plugin_load_ms > 0) {
      text << "registration plugin opened in " << std::fixed << std::setprecision(1)
           << ev.plugin_load_ms << " ms, before the first pair (in no pair's time)\n";
      text.unsetf(std::ios::fixed);
    }
    text << "\n" << pnpba::summaryTable(ev);

    if (!json_path.empty()) writeText(json_path, pnpba::evaluationJson(ev));
    if (!csv_path.empty()) writeText(csv_path, pnpba::evaluationCsv(ev));
    if (!plot_path.empty()) pnpba::writeEvaluationPlot(plot_path, ev.methods, plotPairs(ev));
    if (!trajectory_path.empty()) {
      int gaps = 0;
      writeText(trajectory_path, pnpba::chainedTrajectory(ev, &gaps));
      if (gaps > 0) text << "trajectory: " << gaps << " failed steps kept the last pose\n";
    }
    return 0;
  } catch (const pnpba::Error& e) {
    std::cerr << kProgram << ": " << e.what() << "\n";
    return 2;
  }
}
