// evaluate_tum: every pair (i, i+k), 1 <= k <= K, of a TUM RGB-D sequence, estimated with each
// requested method and scored against the interpolated ground truth (relative pose error).
//
//   evaluate_tum DIR [--camera FILE] [--max-gap 8] [--methods rgbd,pose,none,textbook,opencv]
//                [--json R.json] [--csv R.csv] [--plot R.png] [--trajectory OUT.txt]
//                [--gt-offset SECONDS]
//
// Exit codes: 0 evaluated (failed pairs are reported, not fatal); 2 usage or input error.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "atomic_write.h"
#include "cli_values.h"
#include "evaluation_plot.h"
#include "pnpba/core/error.h"
#include "pnpba/evaluation/evaluation.h"
#include "pnpba/evaluation/opencv_baseline.h"
#include "pnpba/evaluation/tum_dataset.h"
#include "pnpba/pipeline/two_view.h"

namespace {

constexpr const char* kProgram = "evaluate_tum";

struct Frame {
  cv::Mat colour, depth;
};

// TUM freiburg1 (Kinect) colour camera, from the TUM benchmark's calibration.
pnpba::Camera tumFreiburg1() {
  pnpba::Camera c;
  c.pinhole.fx = 517.3, c.pinhole.fy = 516.5, c.pinhole.cx = 318.6, c.pinhole.cy = 255.3;
  c.pinhole.distortion = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};
  c.depth_scale = 5000.0;
  return c;
}

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Evaluate two-view pose methods on a TUM RGB-D sequence against ground truth."};
  std::string folder, camera_path, methods_text = "rgbd,pose,none,textbook,opencv", json_path,
                                   csv_path, plot_path, trajectory_path;
  std::vector<std::string> ba_modes;
  int max_gap = 8, features = pnpba::OrbOptions{}.num_features;
  double gt_offset = 0.0;
  app.add_option("folder", folder,
                 "sequence folder (rgb/, depth/, associate.txt or rgb.txt + "
                 "depth.txt, groundtruth.txt)")
      ->required();
  app.add_option("--camera", camera_path,
                 "camera YAML (default: FOLDER/camera.yaml if present, else TUM freiburg1)");
  app.add_option("--max-gap", max_gap, "evaluate pairs (i, i+k) for k = 1..K")
      ->capture_default_str();
  app.add_option("--methods", methods_text,
                 "comma list: none, pose, textbook, two-camera, rgbd (BA modes), opencv")
      ->capture_default_str();
  app.add_option("--ba", ba_modes, "BA mode(s) to evaluate instead of --methods' BA modes");
  app.add_option("--features", features, "ORB features for every method")->capture_default_str();
  app.add_option("--gt-offset", gt_offset,
                 "seconds added to image stamps before interpolating the ground truth "
                 "(TUM tools' convention; never chosen automatically)")
      ->capture_default_str();
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
    if (max_gap < 1) throw pnpba::Error("--max-gap must be >= 1");
    if (!std::isfinite(gt_offset)) throw pnpba::Error("--gt-offset must be finite");
    std::vector<std::string> methods = splitList(methods_text);
    if (!ba_modes.empty()) {
      std::vector<std::string> kept;
      for (const std::string& m : methods)
        if (m == "opencv") kept.push_back(m);
      methods = ba_modes;
      methods.insert(methods.end(), kept.begin(), kept.end());
    }
    if (methods.empty()) throw pnpba::Error("--methods: no method given");
    for (const std::string& m : methods) {
      if (m != "opencv") pnpba::parseBundleMode(m);  // throws on unknown names
    }
    for (const std::string& out : {json_path, csv_path, plot_path, trajectory_path}) {
      if (out.empty()) continue;
      if (!std::filesystem::is_directory(std::filesystem::absolute(out).parent_path())) {
        throw pnpba::Error(out + ": folder does not exist");
      }
    }
    pnpba::Camera camera = tumFreiburg1();
    if (!camera_path.empty()) {
      camera = pnpba::loadCameraYaml(camera_path);
    } else if (std::filesystem::exists(folder + "/camera.yaml")) {
      camera = pnpba::loadCameraYaml(folder + "/camera.yaml");
    }
    const pnpba::TumSequence seq = pnpba::loadTumSequence(folder, gt_offset);
    std::cout << "sequence " << folder << ": " << seq.frames.size() << " frames ("
              << seq.frames_without_ground_truth << " without ground truth skipped, "
              << seq.frames_missing_files << " listed but missing)\n";

    std::map<int, Frame> cache;
    auto frame = [&](int i) -> const Frame& {
      auto it = cache.find(i);
      if (it != cache.end()) return it->second;
      const std::string rgb = folder + "/" + seq.frames[i].rgb;
      const std::string depth = folder + "/" + seq.frames[i].depth;
      Frame f{cv::imread(rgb, cv::IMREAD_COLOR), cv::imread(depth, cv::IMREAD_UNCHANGED)};
      pnpba::checkTwoViewInputs(f.colour, f.depth, f.colour, cv::Mat(), {rgb, rgb, depth, depth});
      return cache.emplace(i, std::move(f)).first->second;
    };

    std::map<std::string, std::vector<pnpba::PairOutcome>> outcomes;
    nlohmann::json pair_rows = nlohmann::json::array();
    std::vector<pnpba::PlotPair> plot_pairs;
    std::ostringstream csv;
    csv << "method,i,j,k,ok,rot_deg,trans_cm,time_ms,inliers,failure\n";
    std::map<int, pnpba::SE3Quat> consecutive;  // first method's T_(i+1)i for the trajectory
    const int n = static_cast<int>(seq.frames.size());
    for (int i = 0; i < n; ++i) {
      for (auto it = cache.begin(); it != cache.end();) it = it->first < i ? cache.erase(it) : ++it;
      for (int k = 1; k <= max_gap && i + k < n; ++k) {
        const int j = i + k;
        if (!seq.ground_truth[i] || !seq.ground_truth[j]) continue;
        const pnpba::SE3Quat truth =
            pnpba::relativePose(*seq.ground_truth[i], *seq.ground_truth[j]);
        const Frame& a = frame(i);
        const Frame& b = frame(j);
        nlohmann::json row = {{"i", i}, {"j", j}, {"k", k}};
        pnpba::PlotPair plot_pair{i, j, {}};
        std::cout << "pair " << std::setw(3) << i << "-" << std::setw(3) << j << ":";
        for (const std::string& m : methods) {
          pnpba::TwoViewResult r;
          if (m == "opencv") {
            pnpba::OpenCvBaselineOptions o;
            o.features = features;
            r = pnpba::estimateTwoViewOpenCv(a.colour, a.depth, b.colour, camera, o);
          } else {
            pnpba::TwoViewOptions o;
            o.orb.num_features = features;
            o.refinement.mode = pnpba::parseBundleMode(m);
            if (m == "textbook") {  // the textbook recipe, at the same feature count
              o = pnpba::TwoViewOptions::textbookPreset();
              o.orb.num_features = features;
            }
            r = pnpba::estimateTwoView(a.colour, a.depth, b.colour, b.depth, camera, o);
          }
          pnpba::PairOutcome out;
          out.ok = r.ok;
          out.time_ms = r.times_ms.total_ms;
          if (r.ok) out.error = pnpba::relativePoseError(r.T_21, truth);
          outcomes[m].push_back(out);
          plot_pair.errors.push_back(out);
          if (m == methods.front() && k == 1 && r.ok) consecutive[i] = r.T_21;
          std::ostringstream cell;
          if (r.ok) {
            cell << std::fixed << std::setprecision(2) << out.error.rot_deg << "deg "
                 << out.error.trans_cm << "cm";
          } else {
            cell << "failed";
          }
          std::cout << "  " << m << " " << cell.str();
          row[m] = r.ok ? nlohmann::json{{"rot_deg", out.error.rot_deg},
                                         {"trans_cm", out.error.trans_cm},
                                         {"time_ms", out.time_ms},
                                         {"inliers", r.counts.inliers}}
                        : nlohmann::json{{"failed", r.failure}, {"time_ms", out.time_ms}};
          csv << m << "," << i << "," << j << "," << k << "," << (r.ok ? 1 : 0) << ","
              << (r.ok ? out.error.rot_deg : NAN) << "," << (r.ok ? out.error.trans_cm : NAN) << ","
              << out.time_ms << "," << r.counts.inliers << ",\"" << r.failure << "\"\n";
        }
        std::cout << "\n";
        pair_rows.push_back(row);
        plot_pairs.push_back(plot_pair);
      }
    }

    std::cout << "\n"
              << std::left << std::setw(11) << "method" << std::right << std::setw(9) << "med rot"
              << std::setw(9) << "med cm" << std::setw(9) << "mean rot" << std::setw(9) << "mean cm"
              << std::setw(9) << "max rot" << std::setw(9) << "max cm" << std::setw(10)
              << "<1deg&2cm" << std::setw(6) << "fail" << std::setw(9) << "med ms"
              << "\n";
    nlohmann::json method_json;
    for (const std::string& m : methods) {
      const pnpba::MethodSummary s = pnpba::summarize(outcomes[m]);
      const int good = static_cast<int>(std::lround(s.success_rate * s.pairs));
      std::cout << std::left << std::setw(11) << m << std::right << std::fixed
                << std::setprecision(3) << std::setw(9) << s.median_rot_deg << std::setw(9)
                << s.median_trans_cm << std::setw(9) << s.mean_rot_deg << std::setw(9)
                << s.mean_trans_cm << std::setw(9) << s.max_rot_deg << std::setw(9)
                << s.max_trans_cm << std::setw(10)
                << (std::to_string(good) + "/" + std::to_string(s.pairs)) << std::setw(6)
                << s.failures << std::setprecision(1) << std::setw(9) << s.median_time_ms << "\n";
      method_json[m] = {{"median_rot_deg", s.median_rot_deg},
                        {"median_trans_cm", s.median_trans_cm},
                        {"mean_rot_deg", s.mean_rot_deg},
                        {"mean_trans_cm", s.mean_trans_cm},
                        {"max_rot_deg", s.max_rot_deg},
                        {"max_trans_cm", s.max_trans_cm},
                        {"success_rate", s.success_rate},
                        {"failures", s.failures},
                        {"pairs", s.pairs},
                        {"median_time_ms", s.median_time_ms}};
    }
    std::cout.unsetf(std::ios::fixed);

    if (!json_path.empty()) {
      const nlohmann::json j = {{"sequence", folder},
                                {"gt_offset_s", gt_offset},
                                {"max_gap", max_gap},
                                {"methods", method_json},
                                {"pairs", pair_rows}};
      pnpba::writeFileAtomically(json_path, [&j](std::ostream& o) { o << j.dump(2) << "\n"; });
    }
    if (!csv_path.empty()) {
      pnpba::writeFileAtomically(csv_path, [&csv](std::ostream& o) { o << csv.str(); });
    }
    if (!plot_path.empty()) pnpba::writeEvaluationPlot(plot_path, methods, plot_pairs);
    if (!trajectory_path.empty()) {
      // Chain T_wc(i+1) = T_wc(i) * T_(i+1)i^-1 from the first frame's ground truth (identity
      // without it); a failed step keeps the previous pose and is counted.
      pnpba::SE3Quat T_wc = seq.ground_truth.empty() || !seq.ground_truth[0] ? pnpba::SE3Quat()
                                                                             : *seq.ground_truth[0];
      int gaps = 0;
      std::ostringstream traj;
      traj << "# " << methods.front()
           << " estimates chained from frame 0; stamp tx ty tz qx qy qz qw\n";
      for (int i = 0; i < n; ++i) {
        traj << pnpba::formatTumPose(seq.frames[i].rgb_stamp, T_wc) << "\n";
        auto it = consecutive.find(i);
        if (it != consecutive.end()) {
          T_wc = T_wc * it->second.inverse();
        } else if (i + 1 < n) {
          ++gaps;
        }
      }
      pnpba::writeFileAtomically(trajectory_path, [&traj](std::ostream& o) { o << traj.str(); });
      if (gaps > 0) std::cout << "trajectory: " << gaps << " failed steps kept the last pose\n";
    }
    return 0;
  } catch (const pnpba::Error& e) {
    std::cerr << kProgram << ": " << e.what() << "\n";
    return 2;
  }
}
