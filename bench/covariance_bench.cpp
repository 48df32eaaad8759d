// covariance_bench: is the reported covariance of T_21 honest? On rendered pairs with exact
// ground truth, the error as a left perturbation T = exp(d) T_true, d = [rotation; translation]
// in the covariance's order, and its normalised square NEES = d' C^-1 d: 6 on average for an
// honest 6-dof covariance, 95 % of poses below 12.59 (chi-square, 6 dof); rotation and
// translation alone below 7.81 (3 dof). Groups: the wide-baseline sweep's scenes by motion,
// and perturbations a real sensor brings (more depth noise, JPEG colour, intrinsics 1 % off,
// depth scale 1 % off), each split by the path that produced the pose.
//
//   build/bench/covariance_bench [--json FILE] [--plot FILE.png] [--seeds 2] [--motion-sigma 0]
//       [--true-calibration-sigmas] [--focal-sigma F --principal-point-sigma PX
//        --depth-scale-sigma S --min-variance-factor M] [--duplicate-radius PX]
//       [--evidence-cell PX --resolution-px P --depth-resolution D] [--scenes rich,poor,cabinet]
//       [--calibration-error drawn|exact] [--verbose] [--poses FILE]
//       [--sensor tum|realsense|azure|azure-1080p] [--rotations 0,...,60] [--translations 0,...,2]
//       [--conditions clean,depth-noise,jpeg,focal,depth-scale]
//
// `--sensor` renders the sweep through another camera (wide_baseline_pairs.h): a check on
// cameras the model was not calibrated on.
//
// The calibration: the model is told sigmas (a checkerboard calibration's), so a fair test of
// it draws each pose's calibration error from them, as a sensor calibrated that well would
// have it (`--calibration-error drawn`, the default: fx, fy, cx, cy and the depth scale, one
// seeded draw per motion cell and seed, the same under every condition). `exact` gives the
// estimate the renderer's own camera: the one error the calibration term cannot show, so there
// it reads conservative by design. The conditions' fixed errors (focal, depth scale 1 % off)
// come on top of the draw.
#include <CLI/CLI.hpp>
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "bench_output.h"
#include "covariance_cli.h"
#include "guarded_main.h"
#include "pnpba/pipeline/two_view.h"
#include "wide_baseline_pairs.h"

namespace {

using pnpba::SE3Quat;
using pnpba::bench::SweepScene;

constexpr double kChi2_6_95 = 12.592, kChi2_3_95 = 7.815;

struct Sample {
  double nees = 0, nees_rot = 0, nees_trans = 0;
  double baseline_m = 0, rotation_deg = 0;
};

struct Group {
  std::vector<Sample> samples;
  int refused = 0;
};

double quadratic(const Eigen::VectorXd& d, const Eigen::MatrixXd& C) {
  return d.dot(C.ldlt().solve(d));
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The camera's error against the true one in the calibration sensitivity's units
// (covariance_model.h): fx and fy relative, cx and cy in pixels, and the relative growth of
// every point the depth scale causes.
std::vector<double> calibrationErrorOf(const pnpba::Camera& used, const pnpba::Camera& truth) {
  return {used.pinhole.fx / truth.pinhole.fx - 1, used.pinhole.fy / truth.pinhole.fy - 1,
          used.pinhole.cx - truth.pinhole.cx, used.pinhole.cy - truth.pinhole.cy,
          truth.depth_scale / used.depth_scale - 1};
}

// A perturbation of the sensor or the calibration, applied to the rendering options and to the
// camera the estimate is given.
struct Condition {
  std::string name;
  std::string key;               // its --conditions name
  double noise_scale = 1;        // depth noise k times this
  int jpeg_quality = 0;          // colour re-encoded as JPEG
  double focal_error = 0;        // the estimate's fx, fy off by this fraction
  double depth_scale_error = 0;  // the estimate's depth scale off by this fraction
};

template <typename T>
bool contains(const std::vector<T>& list, const T& value) {
  return std::find(list.begin(), list.end(), value) != list.end();
}

void plot(const std::string& path, const std::map<std::string, Group>& groups) {
  // NEES (log scale, 0.1 .. 1e4) against the translation baseline (0 .. 2 m), one dot per pose:
  // blue features, orange depth path, green both; the 95 % bound as a red line.
  const int left = 60, top = 20, w = 560, h = 320;
  cv::Mat img(h + top + 50, w + left + 20, CV_8UC3, cv::Scalar::all(255));
  auto y = [&](double nees) {
    const double t = (std::log10(std::max(nees, 0.1)) + 1.0) / 5.0;
    return top + h - static_cast<int>(h * std::clamp(t, 0.0, 1.0));
  };
  auto x = [&](double m) { return left + static_cast<int>(w * std::clamp(m / 2.1, 0.0, 1.0)); };
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  for (double v : {0.1, 1.0, 10.0, 100.0, 1000.0, 10000.0}) {
    cv::line(img, {left, y(v)}, {left + w, y(v)}, cv::Scalar::all(225));
    char text[16];
    std::snprintf(text, sizeof text, "%g", v);
    cv::putText(img, text, {5, y(v) + 4}, font, 0.4, cv::Scalar::all(0));
  }
  cv::line(img, {left, y(kChi2_6_95)}, {left + w, y(kChi2_6_95)}, cv::Scalar(0, 0, 220), 1);
  for (const auto& [name, g] : groups) {
    if (name.find(", all, ") != std::string::npos) continue;  // each pose once
    const cv::Scalar colour = name.find("/both") != std::string::npos ? cv::Scalar(60, 160, 60)
                              : name.find("/features") != std::string::npos
                                  ? cv::Scalar(200, 110, 30)
                                  : cv::Scalar(30, 130, 240);
    for (const Sample& s : g.samples)
      cv::circle(img, {x(s.baseline_m), y(s.nees)}, 3, colour, cv::FILLED);
  }
  for (double m : {0.0, 0.5, 1.0, 1.5, 2.0}) {
    char text[16];
    std::snprintf(text, sizeof text, "%.1f m", m);
    cv::putText(img, text, {x(m) - 14, top + h + 18}, font, 0.4, cv::Scalar::all(0));
  }
  cv::putText(img,
              "NEES per pose vs baseline: blue features, orange depth path, green both; red: 95%",
              {left - 50, top + h + 40}, font, 0.4, cv::Scalar::all(0));
  pnpba::bench::writePngFile(path, img);
}

}  // namespace

// The bench itself (main: guarded_main.h).
static int benchMain(int argc, char** argv) {
  CLI::App app{"NEES of the two-view covariance on rendered pairs with exact ground truth."};
  std::string json_path, plot_path;
  int seeds = 2;
  app.add_option("--json", json_path,
                 "write {\"groups\": [...], \"refused\": {group: pairs without a pose}}");
  app.add_option("--plot", plot_path, "PNG: NEES against the baseline, one dot per pose");
  app.add_option("--seeds", seeds, "pairs per motion cell")->capture_default_str();
  // The model's knobs, as the CLI has them (defaults: the library's), except the motion term:
  // it stands for what real sensors add and rendered pairs lack (timing, rolling shutter, the
  // ground truth's own error), so it is off here and 0 checks the modelled terms against the
  // renderer's exact truth, as `--motion-sigma 0` tells the CLI for rendered data.
  pnpba::CovarianceModelOptions model;
  model.motion_sigma = 0;
  pnpba::addCovarianceOptions(app, model);
  app.add_option("--min-variance-factor", model.min_variance_factor,
                 "lower bound of the fit's chi2 / dof")
      ->capture_default_str();
  app.add_option("--duplicate-radius", model.duplicate_radius_px,
                 "inliers this close in both images count as one feature, px (0: off)")
      ->capture_default_str();
  int colour_samples = 1;
  app.add_option("--colour-samples", colour_samples,
                 "render colour averaged over n x n rays per pixel (1: the pixel's centre)")
      ->check(CLI::Range(1, 8))
      ->capture_default_str();
  app.add_option("--slide-probe", model.slide_probe_m,
                 "depth path: the slide term's probe along camera 2's axes (m; 0: no term)")
      ->capture_default_str();
  app.add_option("--slide-consistency-sigma", model.slide_consistency_sigma,
                 "depth path: the slide term's consistency noise")
      ->capture_default_str();
  // The calibration sigmas the estimate is told: the library's defaults (a typical factory
  // calibration), or the truth of each condition (0 where the calibration is exact, the error
  // itself where it is off), which checks each term where it applies.
  bool true_calibration_sigmas = false;
  pnpba::AlignmentEvidenceOptions evidence;
  app.add_option("--evidence-cell", evidence.cell_px,
                 "depth path: side of the cells whose errors may share a cause (px)")
      ->capture_default_str();
  app.add_option("--resolution-px", evidence.resolution_px,
                 "depth path: the alignment's resolution in pixels of image motion")
      ->capture_default_str();
  app.add_option("--depth-resolution", evidence.depth_resolution,
                 "depth path: the alignment's resolution in sigmas of the measured depth noise")
      ->capture_default_str();
  double converged_step = pnpba::RgbdAlignmentOptions{}.converged_step;
  app.add_option("--converged-step", converged_step,
                 "depth path: the RGB-D alignment ends a level at steps below this (rad and m)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  double settled_step_sigmas = pnpba::RgbdAlignmentOptions{}.settled_step_sigmas;
  app.add_option("--settled-step-sigmas", settled_step_sigmas,
                 "depth path: the RGB-D alignment ends its full-resolution level, from the third "
                 "step on, at a step within this many of the pose's standard deviations (0: off)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  double brightness_gain_sigma = pnpba::RgbdAlignmentOptions{}.brightness_gain_sigma;
  app.add_option("--brightness-gain-sigma", brightness_gain_sigma,
                 "depth path: frame 2's brightness fitted as a gain and an offset of frame 1's, "
                 "the gain with this prior 1-sigma (0: the offset alone)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  std::vector<std::string> scene_names = {"rich", "poor", "cabinet"};
  std::string sensor_name = "tum";
  app.add_option("--sensor", sensor_name, pnpba::bench::kSensorHelp)
      ->check(CLI::IsMember(pnpba::bench::kSensorNames))
      ->capture_default_str();
  app.add_option("--scenes", scene_names,
                 "scenes of the sweep: rich, poor, cabinet; also tiled (the rich room's texture "
                 "as a 0.5 m tile repeated)")
      ->delimiter(',')
      ->check(CLI::IsMember({"rich", "poor", "cabinet", "tiled"}))
      ->capture_default_str();
  // A part of the sweep, many seeds of a few cells: how a model term behaves where a group's
  // few poses cannot say (docs/two_view.md, the large cells at thirty seeds).
  std::vector<double> rotations = {0, 10, 20, 30, 45, 60};
  std::vector<double> translations = {0.0, 0.25, 0.5, 1.0, 1.5, 2.0};
  app.add_option("--rotations", rotations, "the cells' rotations to run (degrees)")
      ->delimiter(',')
      ->check(CLI::IsMember({0.0, 10.0, 20.0, 30.0, 45.0, 60.0}))
      ->capture_default_str();
  app.add_option("--translations", translations, "the cells' translations to run (m)")
      ->delimiter(',')
      ->check(CLI::IsMember({0.0, 0.25, 0.5, 1.0, 1.5, 2.0}))
      ->capture_default_str();
  std::vector<std::string> condition_keys = {"clean", "depth-noise", "jpeg", "focal",
                                             "depth-scale"};
  app.add_option("--conditions", condition_keys,
                 "the rich room's conditions to run: clean, depth-noise (twice the depth noise), "
                 "jpeg (colour at quality 75), focal (fx, fy 1 % off), depth-scale (1 % off); "
                 "the other scenes run clean only")
      ->delimiter(',')
      ->check(CLI::IsMember({"clean", "depth-noise", "jpeg", "focal", "depth-scale"}))
      ->capture_default_str();
  app.add_flag("--true-calibration-sigmas", true_calibration_sigmas,
               "tell the model each condition's actual calibration error as its 1-sigma "
               "(the camera then has no drawn error)");
  std::string calibration_error = "drawn";
  app.add_option("--calibration-error", calibration_error,
                 "drawn: each pose's camera off by a draw from the sigmas the model is told; "
                 "exact: the renderer's camera")
      ->check(CLI::IsMember({"drawn", "exact"}))
      ->capture_default_str();
  std::string poses_path;
  app.add_option("--poses", poses_path,
                 "write every pose's error d, reported, nominal and calibration covariance, "
                 "calibration sensitivity and the camera's actual error in its units, variance "
                 "factors, the slide sigmas (m) and whether it was fused, as JSON (to study the "
                 "model's terms offline)");
  bool verbose = false;
  app.add_flag("--verbose", verbose,
               "a line per pose: motion, path, NEES (all, rotation, translation), variance factor");
  CLI11_PARSE(app, argc, argv);
  for (const std::string& invalid : {model.validate(), evidence.validate()}) {
    if (!invalid.empty()) {
      std::fprintf(stderr, "covariance_bench: %s\n", invalid.c_str());
      return 2;
    }
  }
  pnpba::bench::checkOutputPaths({json_path, plot_path, poses_path});

  struct Motion {
    std::string name;
    std::vector<double> degrees, metres;
  };
  const std::vector<Motion> motions = {{"small", {0, 10}, {0.0, 0.25}},
                                       {"medium", {20, 30}, {0.5, 1.0}},
                                       {"large", {45, 60}, {1.5, 2.0}}};
  const std::vector<Condition> conditions = {{"clean", "clean"},
                                             {"depth noise x2", "depth-noise", 2.0},
                                             {"jpeg 75", "jpeg", 1.0, 75},
                                             {"focal +1%", "focal", 1.0, 0, 0.01},
                                             {"depth scale +1%", "depth-scale", 1.0, 0, 0.0, 0.01}};
  pnpba::TwoViewOptions options;
  options.covariance = model;
  options.alignment_evidence = evidence;
  options.rgbd_alignment.converged_step = converged_step;
  options.rgbd_alignment.settled_step_sigmas = settled_step_sigmas;
  options.rgbd_alignment.brightness_gain_sigma = brightness_gain_sigma;
  options.alignment_evidence.brightness_gain_sigma = brightness_gain_sigma;
  const pnpba::SyntheticCamera sensor = pnpba::bench::sensorCamera(sensor_name);
  const pnpba::Camera true_camera = pnpba::bench::estimationCamera(sensor);
  std::map<std::string, Group> groups;
  nlohmann::json poses = nlohmann::json::array();
  for (SweepScene scene :
       {SweepScene::kRich, SweepScene::kPoor, SweepScene::kCabinet, SweepScene::kTiled}) {
    const std::string scene_name = pnpba::bench::toString(scene);
    if (!contains(scene_names, scene_name)) continue;
    for (const Condition& condition : conditions) {
      // The perturbations on the rich scene only: the poor room and the cabinet (a Kinect-like
      // sensor's depth: disparity steps, holes at edges) run the slow depth path.
      if (scene != SweepScene::kRich && condition.name != "clean") continue;
      if (!contains(condition_keys, condition.key)) continue;
      for (const Motion& motion : motions) {
        for (double deg : motion.degrees) {
          if (!contains(rotations, deg)) continue;
          for (double metres : motion.metres) {
            if (!contains(translations, metres)) continue;
            for (int s = 0; s < seeds; ++s) {
              pnpba::SyntheticPairOptions o = pnpba::bench::wideBaselinePair(scene, deg, metres, s);
              o.camera = sensor;
              o.camera.colour_samples = colour_samples;
              o.noise.noise_k *= condition.noise_scale;
              o.sensor.jpeg_quality = condition.jpeg_quality;
              const pnpba::SyntheticPair p = pnpba::renderSyntheticPair(o);
              pnpba::Camera camera = true_camera;
              if (calibration_error == "drawn" && !true_calibration_sigmas) {
                pnpba::bench::drawCalibrationError(
                    {model.focal_sigma, model.principal_point_sigma_px, model.depth_scale_sigma},
                    scene, deg, metres, s, &camera);
              }
              camera.pinhole.fx *= 1 + condition.focal_error;
              camera.pinhole.fy *= 1 + condition.focal_error;
              camera.depth_scale *= 1 + condition.depth_scale_error;
              pnpba::TwoViewOptions told = options;
              if (true_calibration_sigmas) {
                told.covariance.focal_sigma = condition.focal_error;
                told.covariance.principal_point_sigma_px = 0;
                told.covariance.depth_scale_sigma = condition.depth_scale_error;
              }
              const pnpba::TwoViewResult r = pnpba::estimateTwoView(
                  p.view1.colour, p.view1.depth, p.view2.colour, p.view2.depth, camera, told);
              const std::string base = std::string(pnpba::bench::toString(scene)) + ", " +
                                       motion.name + ", " + condition.name;
              if (!r.ok || !r.covariance_ok) {
                ++groups[base + "/refused"].refused;
                continue;
              }
              const Eigen::Matrix<double, 6, 1> d = (r.T_21 * p.T_21.inverse()).log();
              const Eigen::Matrix<double, 6, 6>& C = r.covariance;
              Sample sample;
              sample.nees = quadratic(d, C);
              sample.nees_rot = quadratic(d.head<3>(), C.topLeftCorner<3, 3>());
              sample.nees_trans = quadratic(d.tail<3>(), C.bottomRightCorner<3, 3>());
              sample.baseline_m = metres;
              sample.rotation_deg = deg;
              groups[base + "/" + r.path].samples.push_back(sample);
              if (!poses_path.empty()) {
                auto rows = [](const Eigen::Matrix<double, 6, 6>& m) {
                  std::vector<double> v(m.data(), m.data() + 36);
                  return v;
                };
                poses.push_back({{"group", base},
                                 {"path", r.path},
                                 {"degrees", deg},
                                 {"metres", metres},
                                 {"seed", s},
                                 {"d", std::vector<double>(d.data(), d.data() + 6)},
                                 {"covariance", rows(C)},
                                 {"nominal_covariance", rows(r.nominal_covariance)},
                                 {"calibration_covariance",
                                  rows(pnpba::calibrationCovariance(
                                      r.calibration_sensitivity, r.T_21, options.covariance,
                                      pnpba::CalibrationMetric::kDense))},
                                 {"fused", r.fused},
                                 {"slide_sigma_m", std::vector<double>(r.slide_sigma_m.data(),
                                                                       r.slide_sigma_m.data() + 3)},
                                 {"calibration_sensitivity",
                                  std::vector<double>(r.calibration_sensitivity.data(),
                                                      r.calibration_sensitivity.data() + 30)},
                                 {"camera_error", calibrationErrorOf(camera, true_camera)},
                                 {"variance_factor", r.variance_factor},
                                 {"depth_variance_factor", r.depth_variance_factor}});
              }
              if (verbose) {
                std::printf(
                    "pose %-8s %-16s %4.0f deg %4.2f m s%d %-18s nees %7.2f rot %7.2f trans %7.2f "
                    "s2 %.2f depth %.2f\n",
                    pnpba::bench::toString(scene), condition.name.c_str(), deg, metres, s,
                    r.path.c_str(), sample.nees, sample.nees_rot, sample.nees_trans,
                    r.variance_factor, r.depth_variance_factor);
              }
              // Every motion together: the groups the targets read (>= 10 poses).
              groups[std::string(pnpba::bench::toString(scene)) + ", all, " + condition.name + "/" +
                     r.path]
                  .samples.push_back(sample);
            }
          }
        }
      }
      std::fprintf(stderr, "covariance_bench: %s, %s done\n", pnpba::bench::toString(scene),
                   condition.name.c_str());
    }
  }

  if (groups.empty()) {
    std::fprintf(stderr,
                 "covariance_bench: no pair selected (the scenes other than rich run the clean "
                 "condition only)\n");
    return 2;
  }
  nlohmann::json out = {{"groups", nlohmann::json::array()}, {"refused", nlohmann::json::object()}};
  std::printf("%-42s %4s %9s %9s %8s %8s %8s\n", "group / path", "n", "mean", "median", "in95",
              "rot95", "trans95");
  for (const auto& [name, g] : groups) {
    if (g.samples.empty()) {
      // The pairs of a motion and condition that returned no pose: n alone.
      if (g.refused > 0) std::printf("%-42s %4d\n", name.c_str(), g.refused);
      out["refused"][name] = g.refused;
      continue;
    }
    std::vector<double> nees;
    int in = 0, rot_in = 0, trans_in = 0;
    double sum = 0;
    for (const Sample& s : g.samples) {
      nees.push_back(s.nees);
      sum += s.nees;
      in += s.nees <= kChi2_6_95;
      rot_in += s.nees_rot <= kChi2_3_95;
      trans_in += s.nees_trans <= kChi2_3_95;
    }
    const double n = static_cast<double>(g.samples.size());
    std::printf("%-42s %4zu %9.1f %9.1f %7.0f%% %7.0f%% %7.0f%%\n", name.c_str(), g.samples.size(),
                sum / n, median(nees), 100 * in / n, 100 * rot_in / n, 100 * trans_in / n);
    out["groups"].push_back({{"name", name},
                             {"n", g.samples.size()},
                             {"nees_mean", sum / n},
                             {"nees_median", median(nees)},
                             {"inside95", in / n},
                             {"rot_inside95", rot_in / n},
                             {"trans_inside95", trans_in / n}});
  }
  if (!json_path.empty()) pnpba::bench::writeJsonFile(json_path, out, 2);
  if (!poses_path.empty()) pnpba::bench::writeJsonFile(poses_path, {{"poses", poses}}, -1);
  if (!plot_path.empty()) plot(plot_path, groups);
  return 0;
}

int main(int argc, char** argv) {
  return pnpba::bench::guardedMain("covariance_bench", benchMain, argc, argv);
}
