// pose_estimation_3d2d: the two-view RGB-D pose T_21 (camera 2 from camera 1), as the
// textbook program computes it, but robust, measured and with its uncertainty.
//
//   pose_estimation_3d2d img1 img2 depth1 [depth2] [options]
//
// Exit codes: 0 success; 1 the pose could not be estimated (too few matches, pairs or
// inliers: the message says which and how many); 2 usage or input error.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iomanip>
#include <iostream>

#include "cli_values.h"
#include "covariance_cli.h"
#include "one_run_heap.h"
#include "pnpba/core/error.h"
#include "pnpba/core/output_file.h"
#include "pnpba/pipeline/covariance_model.h"
#include "pnpba/pipeline/image_files.h"
#include "pnpba/pipeline/two_view.h"
#include "pnpba/pipeline/two_view_report.h"
#include "tool_entry.h"
#include "two_view_outputs.h"

namespace {

constexpr const char* kProgram = "pose_estimation_3d2d";

}  // namespace

PNPBA_TOOL_MAIN(int argc, char** argv) {
  CLI::App app{
      "Relative pose of two RGB-D views: ORB matches with depth from image 1 -> EPnP in RANSAC "
      "-> bundle adjustment. Prints T = T_21 (X2 = R X1 + t)."};
  std::string img1_path, img2_path, depth1_path, depth2_path;
  std::string camera_path, intrinsics_text, distortion_text,
      ba_name = "rgbd", solver_name = "auto", preset, json_path, matches_png, ply_path,
      match_filter;
  double depth_scale = 0;
  int features = 0;
  int max_feature_pixels = 0;
  std::string detector;
  bool no_sift_retry = false;
  bool include_first_camera = false, verbose = false;
  std::string depth_path_name = "auto";
  pnpba::TwoViewOptions options;
  app.add_option("img1", img1_path, "colour image 1")->required();
  app.add_option("img2", img2_path, "colour image 2")->required();
  app.add_option("depth1", depth1_path, "16-bit depth image of image 1 (0 or 65535: no depth)")
      ->required();
  app.add_option("depth2", depth2_path, "16-bit depth image of image 2 (optional; rgbd mode)");
  app.add_option("--camera", camera_path, "ORB-SLAM2-style camera YAML (Camera.fx, ...)");
  app.add_option("--intrinsics", intrinsics_text, "fx,fy,cx,cy (default 520.9,521.0,325.1,249.7)");
  app.add_option("--distortion", distortion_text, "k1,k2,p1,p2,k3 (OpenCV order)");
  app.add_option("--depth-scale", depth_scale, "depth units per metre (default 5000)");
  app.add_option(
      "--features", features,
      "ORB features per image (default " + std::to_string(pnpba::OrbOptions{}.num_features) + ")");
  app.add_option("--max-feature-pixels", max_feature_pixels,
                 "ORB and AKAZE on a copy of an image of more pixels than this, shrunk by the "
                 "smallest whole factor that brings it within (default " +
                     std::to_string(pnpba::OrbOptions{}.max_pixels) +
                     ", 1280 x 960; 0: every image at its own resolution)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--detector", detector, "keypoints and descriptors: orb (default), sift or akaze");
  app.add_flag("--no-sift-retry", no_sift_retry,
               "do not retry with SIFT when the ORB feature path fails or is refused");
  app.add_option("--match-filter", match_filter, "textbook, ratio (default) or cross-check");
  app.add_option("--ransac-threshold", options.ransac.threshold_px, "inlier threshold, px")
      ->capture_default_str();
  app.add_option("--ba", ba_name, "BA mode: none, pose, textbook, two-camera, rgbd")
      ->capture_default_str();
  app.add_flag("--include-first-camera", include_first_camera, "alias of --ba two-camera");
  app.add_option("--solver", solver_name, "BA back end: auto, native, ceres")
      ->capture_default_str();
  app.add_option("--preset", preset,
                 "textbook: the textbook's front end (500 features, its match filter, no "
                 "undistortion, SOLVEPNP_ITERATIVE) and textbook BA");
  app.add_option("--depth-path", depth_path_name,
                 "depth-only registration: auto (when features fail or are doubtful; needs "
                 "depth2), off, always")
      ->capture_default_str();
  app.add_option("--max-sigma-deg", options.failure_rule.max_sigma_deg,
                 "refuse a pose whose rotation 1-sigma exceeds this (0: off)")
      ->capture_default_str();
  app.add_option("--max-sigma-cm", options.failure_rule.max_sigma_cm,
                 "refuse a pose whose translation 1-sigma exceeds this (0: off)")
      ->capture_default_str();
  app.add_option("--time-budget-ms", options.time_budget_ms,
                 "refuse (rule time_budget) rather than start an optional stage (depth-path "
                 "alignment, SIFT retry, registration) whose expected time does not fit in what "
                 "is left of this many ms, or go on with an alignment past them (33 for 30 Hz; "
                 "0: none)")
      ->capture_default_str();
  app.add_option_function<double>(
         "--brightness-gain-sigma",
         [&options](double sigma) {
           options.rgbd_alignment.brightness_gain_sigma = sigma;
           options.alignment_evidence.brightness_gain_sigma = sigma;
         },
         "depth path: fit frame 2's brightness as a gain and an offset of frame 1's, the gain "
         "with this prior 1-sigma (0.25 for a camera whose auto exposure changes between frames; "
         "0: the offset alone)")
      ->check(CLI::NonNegativeNumber)
      ->default_str("0");
  addCovarianceOptions(app, options.covariance);
  app.add_option("--json", json_path, "write every figure to this JSON file");
  app.add_option("--matches-png", matches_png, "draw matches (inliers green, outliers red)");
  app.add_option("--ply", ply_path, "write inlier points and both camera centres");
  app.add_flag("--verbose", verbose, "the time of every stage and g2o-style per-iteration BA log");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  pnpba::keepOneRunHeap();  // one pair, then exit: its heap is faulted in once

  // With --json to standard output the JSON owns stdout and the human text goes to stderr.
  std::ostream& out = pnpba::isStandardOutput(json_path) ? std::cerr : std::cout;
  try {
    if (!preset.empty()) {
      if (preset != "textbook") throw pnpba::Error("--preset: unknown preset '" + preset + "'");
      const auto ransac_threshold = options.ransac.threshold_px;
      const pnpba::FailureRule rule = options.failure_rule;
      options = pnpba::TwoViewOptions::textbookPreset();
      options.ransac.threshold_px = ransac_threshold;
      options.failure_rule.max_sigma_deg = rule.max_sigma_deg;
      options.failure_rule.max_sigma_cm = rule.max_sigma_cm;
      if (app.count("--ba") == 0) ba_name = "textbook";
    }
    pnpba::Camera camera;
    if (!camera_path.empty()) camera = pnpba::loadCameraYaml(camera_path);
    if (!intrinsics_text.empty()) {
      const auto k = pnpba::parseNumberList(intrinsics_text, 4, "--intrinsics");
      camera.pinhole.fx = k[0], camera.pinhole.fy = k[1], camera.pinhole.cx = k[2],
      camera.pinhole.cy = k[3];
    }
    if (!distortion_text.empty()) {
      const auto d = pnpba::parseNumberList(distortion_text, 5, "--distortion");
      std::copy(d.begin(), d.end(), camera.pinhole.distortion.begin());
    }
    if (app.count("--depth-scale")) camera.depth_scale = depth_scale;
    const std::string camera_problem = camera.validate();
    if (!camera_problem.empty()) throw pnpba::Error("camera: " + camera_problem);
    if (app.count("--features")) options.orb.num_features = features;
    if (app.count("--max-feature-pixels")) options.orb.max_pixels = max_feature_pixels;
    if (!detector.empty()) options.orb.detector = pnpba::parseDetector(detector);
    if (no_sift_retry) options.retry_with_sift = false;
    if (!match_filter.empty()) options.matching.filter = pnpba::parseMatchFilter(match_filter);
    if (include_first_camera) ba_name = "two-camera";
    options.refinement.mode = pnpba::parseBundleMode(ba_name);
    if (app.count("--depth-path")) options.depth_path = pnpba::parseDepthPath(depth_path_name);
    options.refinement.solver = pnpba::parseSolverBackend(solver_name);
    options.refinement.verbose = verbose;
    std::vector<std::string> ba_log;  // printed after the initial pose, in the textbook's order
    options.refinement.log = [&ba_log](const std::string& line) { ba_log.push_back(line); };
    const std::string problem = options.validate();
    if (!problem.empty()) throw pnpba::Error(problem);
    for (const std::string& out : {json_path, matches_png, ply_path}) {
      if (!out.empty()) pnpba::checkOutputPath(out);
    }

    const pnpba::TwoViewImages images =
        pnpba::readTwoViewImages(img1_path, img2_path, depth1_path, depth2_path);
    const cv::Mat &image1 = images.image1, &image2 = images.image2;
    const cv::Mat &depth1 = images.depth1, &depth2 = images.depth2;
    const pnpba::TwoViewInputNames names{img1_path, img2_path, depth1_path, depth2_path,
                                         camera_path.empty() ? "the camera" : camera_path};
    pnpba::checkTwoViewInputs(image1, depth1, image2, depth2, names);
    pnpba::checkCameraSize(image1, camera, names);

    const pnpba::TwoViewResult r =
        pnpba::estimateTwoView(image1, depth1, image2, depth2, camera, options);
    out << "found " << r.counts.matches << " matches\n";
    out << r.counts.pairs << " 3d-2d pairs\n";
    if (verbose) out << pnpba::stageTimesLine(r.times_ms) << "\n";
    if (!r.ok) {
      if (!json_path.empty()) pnpba::writeTwoViewJson(json_path, r, ba_name);
      std::cerr << kProgram << ": estimation failed: " << r.failure << "\n";
      return 1;
    }
    const Eigen::Matrix4d T0 = r.T_init.to_homogeneous_matrix();
    out << r.counts.inliers << " inliers\n";
    out << "R=\n" << T0.topLeftCorner<3, 3>() << "\n";
    out << "t=\n" << T0.topRightCorner<3, 1>() << "\n";
    for (const std::string& line : ba_log) out << line << "\n";
    out << "bundle adjustment: " << ba_name << ", solver " << r.solver << ", " << r.ba_iterations
        << " iterations, chi2 " << std::setprecision(10) << r.chi2_initial << " -> " << r.chi2_final
        << std::setprecision(6) << "\n";
    out << "optimization costs time: " << r.times_ms.ba_ms / 1000.0 << " seconds.\n";
    if (r.covariance_ok) {
      const auto sd = r.covariance.diagonal().cwiseSqrt();
      out << "pose 1-sigma (fit, calibration and motion): rotation " << std::setprecision(3)
          << sd.head<3>().norm() * 180.0 / M_PI << " deg, translation "
          << sd.tail<3>().norm() * 100.0 << " cm" << std::setprecision(6) << "\n";
      // The calibration's share: what a better calibration would take off (covariance_model.h).
      const pnpba::CovarianceModelOptions& model = options.covariance;
      const pnpba::Matrix6d calibration = pnpba::calibrationCovariance(
          r.calibration_sensitivity, r.T_21, model, pnpba::CalibrationMetric::kDense);
      if (!calibration.isZero()) {
        const pnpba::PoseSigmas own = pnpba::poseSigmas(calibration);
        out << "of which the calibration (fx, fy " << 100 * model.focal_sigma << " %, cx, cy "
            << model.principal_point_sigma_px << " px, depth scale "
            << 100 * model.depth_scale_sigma << " %): rotation " << std::setprecision(3) << own.deg
            << " deg, translation " << own.cm << " cm" << std::setprecision(6) << "\n";
      }
      if (!r.slide_sigma_m.isZero()) {
        const Eigen::Vector3d cm = 100.0 * r.slide_sigma_m;
        out << "of which the slide the depths allow along camera 2's x, y, z: "
            << std::setprecision(2) << cm.x() << ", " << cm.y() << ", " << cm.z() << " cm"
            << std::setprecision(6) << "\n";
      }
    }
    out << "\nafter optimization:\nT=\n" << r.T_21.to_homogeneous_matrix() << "\n";

    if (!json_path.empty()) pnpba::writeTwoViewJson(json_path, r, ba_name);
    if (!matches_png.empty()) pnpba::writeMatchesPng(matches_png, image1, image2, r);
    if (!ply_path.empty()) pnpba::writeTwoViewPly(ply_path, r);
    return 0;
  } catch (const pnpba::Error& e) {
    std::cerr << kProgram << ": " << e.what() << "\n";
    return 2;
  }
}
