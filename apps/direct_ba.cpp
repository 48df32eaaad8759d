// direct_ba: photometric bundle adjustment of camera poses and points (4x4 patch intensities,
// Huber kernel), the active set of edges re-decided every round.
//
//   direct_ba --poses poses.txt --points points.txt --images DIR [--fx .. --fy .. --cx .. --cy ..]
//       [--huber 5.128] [--iterations 100] [--round 10] [--free-first-pose] [--inverse-depth]
//       [--threads 1]
//       [--output-poses OUT.txt] [--ply OUT.ply] [--json R.json] [--verbose]
//
// Images are DIR/0.png, DIR/1.png, ... one per pose, read as grey. Exit codes: 0 solved;
// 2 usage or input error.
#include "pnpba/direct/direct_ba.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>  // the flags; the codecs come through pnpba::imageio

#include "pnpba/core/error.h"
#include "pnpba/core/output_file.h"
#include "pnpba/imageio/image_codec.h"
#include "tool_entry.h"

namespace {

constexpr const char* kProgram = "direct_ba";

std::shared_ptr<pnpba::GrayImage> readGray(const std::string& path) {
  if (!std::filesystem::exists(path)) throw pnpba::Error(path + ": cannot open file");
  const cv::Mat m = pnpba::loadImage(path, cv::IMREAD_GRAYSCALE);
  if (m.empty()) throw pnpba::Error(path + ": not an image OpenCV can decode");
  auto image = std::make_shared<pnpba::GrayImage>();
  image->width = m.cols;
  image->height = m.rows;
  image->pixels.assign(m.begin<uchar>(), m.end<uchar>());
  return image;
}

void writePly(const std::string& path, const pnpba::DirectBaProblem& p) {
  pnpba::writeOutputFile(path, [&p](std::ostream& out) {
    out << "ply\nformat ascii 1.0\ncomment pnpba direct BA: points coloured by patch centre "
           "intensity, cameras green\nelement vertex "
        << p.points.size() + p.poses.size()
        << "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
           "property uchar green\nproperty uchar blue\nend_header\n";
    for (const pnpba::DirectPoint& q : p.points) {
      // Patch centre: offset (0, 0), k = 4 * 2 + 2.
      const int g = static_cast<int>(std::clamp(q.patch[10], 0.0, 255.0));
      out << q.Pw.x() << " " << q.Pw.y() << " " << q.Pw.z() << " " << g << " " << g << " " << g
          << "\n";
    }
    for (const pnpba::DirectPose& c : p.poses) {
      const Eigen::Vector3d centre = c.T_cw.inverse().translation();
      out << centre.x() << " " << centre.y() << " " << centre.z() << " 0 255 0\n";
    }
  });
}

}  // namespace

PNPBA_TOOL_MAIN(int argc, char** argv) {
  CLI::App app{"Direct (photometric) bundle adjustment of poses and points."};
  std::string poses_path, points_path, images_dir, output_poses, ply_path, json_path;
  pnpba::DirectBaOptions options;
  pnpba::DirectBaProblem problem;
  bool free_first = false, verbose = false;
  app.add_option("--poses", poses_path, "poses: timestamp tx ty tz qx qy qz qw (T_cw) per line")
      ->required();
  app.add_option("--points", points_path, "points: x y z and 16 patch intensities per line")
      ->required();
  app.add_option("--images", images_dir, "folder with 0.png, 1.png, ... (one per pose)")
      ->required();
  app.add_option("--fx", problem.fx)->capture_default_str();
  app.add_option("--fy", problem.fy)->capture_default_str();
  app.add_option("--cx", problem.cx)->capture_default_str();
  app.add_option("--cy", problem.cy)->capture_default_str();
  app.add_option("--huber", options.huber_delta,
                 "Huber width on |e| of the 16-vector (default sqrt(chi2 95%, 16 dof))")
      ->capture_default_str();
  app.add_option("--iterations", options.iterations, "LM iterations")->capture_default_str();
  app.add_option("--round", options.iterations_per_round,
                 "iterations between re-decisions of the active edges (0: never)")
      ->capture_default_str();
  app.add_flag("--free-first-pose", free_first, "optimise pose 0 too (default: held fixed)");
  app.add_flag("--inverse-depth", options.inverse_depth,
               "points as inverse depth (a, b, rho) relative to camera 0, not world xyz");
  app.add_option("--threads", options.threads,
                 "threads for the edges' errors and Jacobians (results identical for any count)")
      ->capture_default_str();
  app.add_option("--output-poses", output_poses, "refined poses, same format as --poses");
  app.add_option("--ply", ply_path, "points (patch centre grey) and camera centres");
  app.add_option("--json", json_path, "summary as JSON");
  app.add_flag("--verbose", verbose, "progress every iteration (default: every 10)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    options.fix_first_pose = !free_first;
    const std::string bad = options.validate();
    if (!bad.empty()) throw pnpba::Error(bad);
    for (double v : {problem.fx, problem.fy, problem.cx, problem.cy}) {
      if (!std::isfinite(v)) throw pnpba::Error("intrinsics must be finite");
    }
    if (!(problem.fx > 0) || !(problem.fy > 0)) throw pnpba::Error("--fx and --fy must be > 0");
    for (const std::string& out : {output_poses, ply_path, json_path}) {
      if (!out.empty()) pnpba::checkOutputPath(out);
    }
    // An output on standard output owns it; the human text goes to stderr.
    FILE* const text =
        pnpba::anyIsStandardOutput({output_poses, ply_path, json_path}) ? stderr : stdout;
    problem.poses = pnpba::readDirectPoses(poses_path);
    problem.points = pnpba::readDirectPoints(points_path);
    for (size_t k = 0; k < problem.poses.size(); ++k) {
      problem.images.push_back(readGray(images_dir + "/" + std::to_string(k) + ".png"));
    }
    std::fprintf(text, "%zu poses, %zu points, %zu edges\n", problem.poses.size(),
                 problem.points.size(), problem.poses.size() * problem.points.size());
    std::fprintf(text, "%5s %14s %8s %9s\n", "iter", "cost", "active", "time_s");
    options.progress = [verbose, text](const pnpba::DirectBaIteration& it) {
      if (verbose || it.iteration % 10 == 0) {
        std::fprintf(text, "%5d %14.6e %8zu %9.2f\n", it.iteration, it.cost, it.active_edges,
                     it.time_s);
        std::fflush(stdout);
      }
    };
    const pnpba::DirectBaSummary s = pnpba::solveDirectBa(problem, options);
    std::fprintf(text, "\ncost (1/2 sum rho): %.6e -> %.6e\n", s.initial_cost, s.final_cost);
    std::fprintf(text, "active edges: %zu -> %zu of %zu\n", s.active_edges_initial,
                 s.active_edges_final, s.edges);
    std::fprintf(text, "%d iterations in %d rounds, %.2f s; largest point motion %.3f m\n",
                 s.iterations, s.rounds, s.time_s, s.max_point_motion_m);
    for (size_t k = 0; k < s.pose_change.size(); ++k) {
      std::fprintf(text, "pose %zu moved %.4f deg, %.4f m\n", k, s.pose_change[k].rotation_deg,
                   s.pose_change[k].translation_m);
    }
    if (!output_poses.empty()) {
      pnpba::writeOutputFile(output_poses, [&problem](std::ostream& out) {
        pnpba::writeDirectPoses(out, problem.poses);
      });
    }
    if (!ply_path.empty()) writePly(ply_path, problem);
    if (!json_path.empty()) {
      nlohmann::json changes = nlohmann::json::array();
      for (const auto& c : s.pose_change) {
        changes.push_back({{"rotation_deg", c.rotation_deg}, {"translation_m", c.translation_m}});
      }
      const nlohmann::json j = {{"initial_cost", s.initial_cost},
                                {"final_cost", s.final_cost},
                                {"active_edges_initial", s.active_edges_initial},
                                {"active_edges_final", s.active_edges_final},
                                {"iterations", s.iterations},
                                {"time_s", s.time_s},
                                {"max_point_motion_m", s.max_point_motion_m},
                                {"pose_change", changes}};
      pnpba::writeOutputFile(json_path, [&j](std::ostream& out) { out << j.dump(2) << "\n"; });
    }
    return 0;
  } catch (const pnpba::Error& e) {
    std::cerr << kProgram << ": " << e.what() << "\n";
    return 2;
  }
}
