// wide_baseline_bench: the two-view pose across motions it was not tuned on. Renders pairs of
// the closed synthetic room (rich and poor texture) and the plain cabinet by a wall (Kinect-like
// depth, JPEG colour) for every rotation x translation cell, a
// few seeds each (a random near-vertical axis per seed; camera 2 keeps looking at the room),
// runs pnpba's default pipeline and the OpenCV baseline side by side, and counts per cell:
//   ok       within 2 deg and 5 cm of the ground truth
//   refused  no pose returned (exit 1 in the CLI)
//   wrong    returned but more than 10 deg or 50 cm off
// (returned poses between those limits are neither ok nor wrong).
//
//   build/bench/wide_baseline_bench [--seeds 3] [--json cells.json] [--plot cells.png]
//       [--methods default,opencv,features,depth] [--scenes rich,poor,cabinet] [--rotations
//       0,10,...] [--translations 0,...] [--smooth-cabinet-depth]
//       [--depth-noise K] [--kinect-rooms] [--exposure-gain G] [--motion-blur PX] [--resize F]
//       [--sensor tum|realsense|azure|azure-1080p] [--axis pan|tilt|roll] [--render-each]
//
// Methods: default (the pipeline as shipped), opencv (evaluation/opencv_baseline.h, same
// feature count), features (the default with the depth path off), depth (the depth-only
// registration alone, unrefined).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "bench_output.h"
#include "guarded_main.h"
#include "pnpba/evaluation/evaluation.h"
#include "pnpba/evaluation/opencv_baseline.h"
#include "pnpba/pipeline/depth_registration.h"
#include "pnpba/pipeline/two_view.h"
#include "pnpba/synthetic/synthetic_pair.h"
#include "resized_pair.h"
#include "wide_baseline_pairs.h"

namespace {

using pnpba::SE3Quat;

std::vector<double> parseList(const std::string& text, const std::string& option) {
  std::vector<double> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    size_t used = 0;
    double value = 0;
    try {
      value = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(value)) {
      throw std::runtime_error(option + ": '" + item + "' is not a number");
    }
    out.push_back(value);
  }
  return out;
}

struct Cell {
  int pairs = 0, ok = 0, refused = 0, wrong = 0;
  double time_ms = 0;
};

struct Outcome {
  bool returned = false;
  SE3Quat T;
  double time_ms = 0;
  std::string detail;  // path or failure, consistency, fitness (--verbose)
};

bool g_verbose = false;
// --render-each: each pair rendered just before its methods run rather than a batch first.
bool g_render_each = false;

pnpba::DepthRegistrationOptions g_registration;
int g_features = pnpba::OrbOptions{}.num_features;
int g_max_feature_pixels = pnpba::OrbOptions{}.max_pixels;
std::string g_detector = "orb", g_match_filter = "ratio";
int g_orb_levels = 0;  // 0: the default
bool g_no_sift_retry = false;
// The cabinet's depth without the Kinect's disparity steps (the same Gaussian noise, holes and
// depth-to-colour offset): a smoother sensor, as time-of-flight cameras give.
bool g_smooth_cabinet_depth = false;
double g_repeat_max_shift = pnpba::RepeatSearchOptions{}.max_shift_m;
double g_free_slide = pnpba::RepeatSearchOptions{}.free_slide_m;
double g_depth_noise = 0;  // 0: each scene's own
// The rooms seen through the cabinet's Kinect-like sensor (SensorEffects::kinectLike).
bool g_kinect_rooms = false;
// Frame 2's colour scaled by this (an auto-exposure change between the frames; 1: none).
double g_exposure_gain = 1.0;
// The depth path's brightness model: the gain's prior 1-sigma (0: the offset alone).
double g_brightness_gain_sigma = pnpba::RgbdAlignmentOptions{}.brightness_gain_sigma;
// Frame 2's colour smeared over this many pixels along the image rows (a camera panning while the
// shutter is open; depth sensors integrate far less and stay sharp); 0: none.
int g_motion_blur_px = 0;
// Every pair as a sensor of this many times the renderer's 640 x 480 sees it
// (tests/support/resized_pair.h); 1: as rendered.
double g_resize = 1.0;
// The camera the pairs are rendered through: the textbook's (TUM-like, 640 x 480, depth x5000)
// or another sensor's size, field of view and depth unit.
std::string g_sensor = "tum";
std::string g_axis = "pan";  // --axis: what camera 2 turns about (wide_baseline_pairs.h)
// The camera the estimate is given: the renderer's own, or off by a seeded draw of a
// checkerboard calibration's error (--calibration-error drawn; covariance_bench's draw).
std::string g_calibration_error = "exact";

Outcome run(const std::string& method, const pnpba::SyntheticPair& p, const pnpba::Camera& camera) {
  Outcome out;
  const auto start = std::chrono::steady_clock::now();
  if (method == "depth") {
    const pnpba::DepthRegistration r = pnpba::registerDepthImages(
        p.view1.depth, p.view2.depth, camera.pinhole, camera.depth_scale, g_registration);
    out.returned = r.ok;
    out.T = r.T_21;
    char text[200];
    std::snprintf(
        text, sizeof text,
        "prepare %.0f global %.0f icp %.0f ms, points %d %d voxel %.3f | sigma %.3f deg %.2f cm "
        "fit %.2f rmse %.3f",
        r.prepare_ms, r.global_ms, r.icp_ms, r.points1, r.points2, r.voxel_m,
        std::sqrt(r.covariance.topLeftCorner<3, 3>().trace()) * 180 / M_PI,
        std::sqrt(r.covariance.bottomRightCorner<3, 3>().trace()) * 100, r.fitness, r.inlier_rmse);
    out.detail = text;
  } else if (method == "opencv") {
    pnpba::OpenCvBaselineOptions o;
    o.features = g_features;
    const pnpba::TwoViewResult r =
        pnpba::estimateTwoViewOpenCv(p.view1.colour, p.view1.depth, p.view2.colour, camera, o);
    out.returned = r.ok;
    out.T = r.T_21;
  } else {
    pnpba::TwoViewOptions o;
    o.registration = g_registration;
    o.orb.num_features = g_features;
    o.orb.detector = pnpba::parseDetector(g_detector);
    if (g_orb_levels > 0) o.orb.levels = g_orb_levels;
    o.orb.max_pixels = g_max_feature_pixels;
    o.retry_with_sift = !g_no_sift_retry;
    o.matching.filter = pnpba::parseMatchFilter(g_match_filter);
    o.rgbd_alignment.brightness_gain_sigma = g_brightness_gain_sigma;
    o.alignment_evidence.brightness_gain_sigma = g_brightness_gain_sigma;
    o.repeat_search.max_shift_m = g_repeat_max_shift;
    o.repeat_search.free_slide_m = g_free_slide;
    if (method == "features") o.depth_path = pnpba::DepthPath::kOff;
    const pnpba::TwoViewResult r = pnpba::estimateTwoView(p.view1.colour, p.view1.depth,
                                                          p.view2.colour, p.view2.depth, camera, o);
    out.returned = r.ok;
    out.T = r.T_21;
    char text[600];
    std::snprintf(text, sizeof text,
                  "%s | pairs %d inl %d cons %.2f fit %.2f overlap %.2f photo %.2f candidates "
                  "%d (%d again) sigma %.3f %.2f | %s",
                  r.ok ? r.path.c_str() : r.failure_rule.c_str(), r.counts.pairs, r.counts.inliers,
                  r.depth_consistency, r.registration_fitness, r.overlap, r.photometric_agreement,
                  r.counts.depth_candidates, r.counts.depth_duplicates,
                  std::sqrt(r.covariance.topLeftCorner<3, 3>().trace()) * 180 / M_PI,
                  std::sqrt(r.covariance.bottomRightCorner<3, 3>().trace()) * 100,
                  r.failure.c_str());
    out.detail = text;
  }
  out.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return out;
}

// One pair of the sweep: its cell (rotation, translation) and seed.
struct SweepPoint {
  double deg = 0, metres = 0;
  int seed = 0;
};

// A pair rendered and prepared as the options ask (sensor, exposure, blur, calibration error,
// resize), with the camera its estimate is given.
struct PreparedPair {
  SweepPoint at;
  pnpba::SyntheticPair pair;
  pnpba::Camera camera;
};

// The images one batch of rendered pairs may hold before they are estimated: the sweep at 640 x
// 480 (3 MB a pair) in one batch, a 1920 x 1080 camera's (20 MB a pair) in a few.
constexpr size_t kBatchBytes = size_t{1} << 30;

size_t imageBytes(const pnpba::SyntheticPair& p) {
  const auto bytes = [](const cv::Mat& m) { return m.total() * m.elemSize(); };
  return bytes(p.view1.colour) + bytes(p.view1.depth) + bytes(p.view2.colour) +
         bytes(p.view2.depth);
}

// Empty where a view has no depth (the camera turned away from the scene).
std::optional<PreparedPair> preparePair(pnpba::bench::SweepScene scene, const SweepPoint& at,
                                        const pnpba::SyntheticCamera& sensor,
                                        const pnpba::Camera& camera) {
  pnpba::SyntheticPairOptions o = pnpba::bench::wideBaselinePair(
      scene, at.deg, at.metres, at.seed, pnpba::bench::parseSweepAxis(g_axis));
  if (scene == pnpba::bench::SweepScene::kCabinet && g_smooth_cabinet_depth) {
    o.sensor.disparity_fb = 0;
  }
  if (scene != pnpba::bench::SweepScene::kCabinet && g_kinect_rooms) {
    o.sensor = pnpba::SensorEffects::kinectLike();
  }
  if (g_depth_noise > 0) o.noise.noise_k = g_depth_noise;
  o.camera = sensor;
  PreparedPair out{at, pnpba::renderSyntheticPair(o), camera};
  pnpba::SyntheticPair& pair = out.pair;
  if (g_exposure_gain != 1.0) {
    pair.view2.colour.convertTo(pair.view2.colour, -1, g_exposure_gain);
  }
  if (g_motion_blur_px > 1) {
    cv::blur(pair.view2.colour, pair.view2.colour, cv::Size(g_motion_blur_px, 1));
  }
  if (g_calibration_error == "drawn") {
    pnpba::bench::drawCalibrationError({}, scene, at.deg, at.metres, at.seed, &out.camera);
  }
  if (g_resize != 1.0) {
    pnpba::bench::resizePair(g_resize, &pair.view1.colour, &pair.view1.depth, &pair.view2.colour,
                             &pair.view2.depth, &out.camera);
  }
  if (!pnpba::bench::bothViewsHaveDepth(pair)) return std::nullopt;
  return out;
}

// A cell's counts and times per method, over its seeds.
struct CellRuns {
  std::map<std::string, Cell> counts;
  std::map<std::string, std::vector<double>> times;
};

// One panel per (scene, method): rows are rotations, columns translations; a cell mixes green
// (ok share), grey (refused) and pale yellow (returned but outside 2 deg / 5 cm); a red frame
// with the count marks wrong poses.
void writePlot(const std::string& path, const nlohmann::json& cells,
               const std::vector<std::string>& methods, const std::vector<double>& rotations,
               const std::vector<double>& translations) {
  const int cell = 46, left = 60, top = 50, gap = 60;
  const int panel_w = left + cell * static_cast<int>(translations.size());
  const int panel_h = top + cell * static_cast<int>(rotations.size()) + 30;
  const int cols = static_cast<int>(methods.size());
  // One row of panels per scene, in the order the sweep ran them.
  std::vector<std::string> scenes;
  for (const auto& c : cells) {
    if (std::find(scenes.begin(), scenes.end(), c["scene"]) == scenes.end()) {
      scenes.push_back(c["scene"]);
    }
  }
  const int rows = std::max<int>(1, static_cast<int>(scenes.size()));
  cv::Mat canvas(rows * panel_h + (rows - 1) * gap, cols * panel_w + (cols - 1) * gap + 20, CV_8UC3,
                 cv::Scalar::all(255));
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  for (const auto& c : cells) {
    const std::string scene = c["scene"];
    const int t = static_cast<int>(std::find(scenes.begin(), scenes.end(), scene) - scenes.begin());
    const int m =
        static_cast<int>(std::find(methods.begin(), methods.end(), c["method"]) - methods.begin());
    const int r = static_cast<int>(
        std::find(rotations.begin(), rotations.end(), c["rotation_deg"].get<double>()) -
        rotations.begin());
    const int k = static_cast<int>(
        std::find(translations.begin(), translations.end(), c["translation_m"].get<double>()) -
        translations.begin());
    const cv::Point origin(10 + m * (panel_w + gap), t * (panel_h + gap));
    const double pairs = c["pairs"].get<double>();
    const double ok = c["ok"].get<double>() / pairs, refused = c["refused"].get<double>() / pairs;
    const cv::Rect box(origin.x + left + k * cell, origin.y + top + r * cell, cell - 2, cell - 2);
    // Mix of green (ok), grey (refused) and pale yellow (returned, between ok and wrong).
    const double rest = std::max(0.0, 1.0 - ok - refused);
    const cv::Scalar colour = ok * cv::Scalar(60, 200, 60) + refused * cv::Scalar(170, 170, 170) +
                              rest * cv::Scalar(150, 230, 255);
    cv::rectangle(canvas, box, colour, cv::FILLED);
    if (c["wrong"].get<int>() > 0) {
      cv::rectangle(canvas, box, cv::Scalar(0, 0, 220), 3);
      cv::putText(canvas, std::to_string(c["wrong"].get<int>()),
                  box.tl() + cv::Point(cell / 2 - 6, cell / 2 + 6), font, 0.5,
                  cv::Scalar(0, 0, 200), 2);
    }
    if (r == 0 && k == 0) {
      cv::putText(canvas, scene + ": " + std::string(c["method"]), origin + cv::Point(left, 22),
                  font, 0.55, cv::Scalar::all(0), 1);
      for (size_t i = 0; i < rotations.size(); ++i) {
        cv::putText(canvas, std::to_string(static_cast<int>(rotations[i])) + "deg",
                    origin + cv::Point(5, top + static_cast<int>(i) * cell + cell / 2 + 5), font,
                    0.4, cv::Scalar::all(0), 1);
      }
      for (size_t i = 0; i < translations.size(); ++i) {
        char text[16];
        std::snprintf(text, sizeof text, "%.2gm", translations[i]);
        cv::putText(canvas, text,
                    origin + cv::Point(left + static_cast<int>(i) * cell + 6,
                                       top + static_cast<int>(rotations.size()) * cell + 18),
                    font, 0.4, cv::Scalar::all(0), 1);
      }
    }
  }
  pnpba::bench::writePngFile(path, canvas);
}

}  // namespace

// The bench itself (main: guarded_main.h).
static int benchMain(int argc, char** argv) {
  CLI::App app{"Wide-baseline sweep of the two-view pose on rendered pairs with ground truth."};
  int seeds = 3;
  std::string plot_path, json_path,
      methods_text = "default,opencv", scenes_text = "rich,poor,cabinet",
      global_text = pnpba::toString(g_registration.method), rotations_text = "0,10,20,30,45,60",
      translations_text = "0,0.25,0.5,1,1.5,2";
  app.add_option("--seeds", seeds, "pairs per cell")->capture_default_str();
  app.add_option("--json", json_path, "write the cells as JSON");
  app.add_option("--plot", plot_path,
                 "PNG: a grid per scene and method (green = ok share, grey = refused, red "
                 "frame = wrong poses)");
  app.add_option("--methods", methods_text, "default, opencv, features, depth")
      ->capture_default_str();
  app.add_option(
         "--scenes", scenes_text,
         "rich, poor (the closed room's textures), cabinet (a plain cabinet by a wall, "
         "Kinect-like depth, JPEG colour); also tiled (the rich room's texture as a 0.5 m "
         "tile repeated), structure (a plain zig-zag of panels, the cabinet's sensor), corridor "
         "(a plain wall on a plain floor, the cabinet's sensor) and poster (a rich poster on a "
         "plain wall, one plane, the cabinet's sensor)")
      ->capture_default_str();
  app.add_option("--rotations", rotations_text, "degrees")->capture_default_str();
  app.add_option("--translations", translations_text, "metres")->capture_default_str();
  app.add_option("--voxel", g_registration.voxel_m, "registration voxel (m)")
      ->capture_default_str();
  app.add_option("--stride", g_registration.pixel_stride, "registration pixel stride")
      ->capture_default_str();
  app.add_option("--fine-voxel", g_registration.fine_voxel_m)->capture_default_str();
  app.add_option("--ransac-iterations", g_registration.ransac_iterations)->capture_default_str();
  app.add_option("--icp-iterations", g_registration.icp_iterations, "0: none")
      ->capture_default_str();
  app.add_option("--max-range", g_registration.max_range_m)->capture_default_str();
  app.add_option("--fpfh-neighbours", g_registration.fpfh_neighbours,
                 "the registration's FPFH neighbours at most")
      ->capture_default_str();
  app.add_option("--max-points", g_registration.max_points,
                 "the registration's cloud 1 at most about this many points (0: no limit)")
      ->capture_default_str();
  app.add_option("--voxel-fraction", g_registration.voxel_depth_fraction,
                 "registration voxel as a fraction of the median depth (0: --voxel)")
      ->capture_default_str();
  app.add_option("--global", global_text, "ransac, open3d-ransac, fast or candidates")
      ->check(CLI::IsMember({"ransac", "open3d-ransac", "fast", "candidates"}))
      ->capture_default_str();
  app.add_option("--registration-seed", g_registration.seed,
                 "the registration's RANSAC seed (another seed: another sample of its draws)")
      ->capture_default_str();
  app.add_flag("--verbose", g_verbose, "a line per pair and method");
  app.add_flag("--render-each", g_render_each,
               "render each pair just before its methods rather than a batch of pairs before the "
               "first is timed (the renderer's work between estimates then slows the next one)");
  app.add_option("--detector", g_detector, "orb, sift or akaze (pnpba's methods)")
      ->check(CLI::IsMember({"orb", "sift", "akaze"}))
      ->capture_default_str();
  app.add_option("--orb-levels", g_orb_levels, "ORB pyramid levels (0: the default, 4)");
  app.add_option("--max-feature-pixels", g_max_feature_pixels,
                 "ORB on a copy of an image of more pixels than this, shrunk by the smallest "
                 "whole factor that brings it within (0: every image at its own resolution)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_flag("--no-sift-retry", g_no_sift_retry,
               "no SIFT retry where ORB fails (to compare front ends alone)");
  app.add_option("--repeat-max-shift", g_repeat_max_shift,
                 "the depth path's search for a twin along a repeat, up to this shift (m; 0: no "
                 "search)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--free-slide", g_free_slide,
                 "the repeat search also takes a slide the depths leave free this far as a twin "
                 "(m; 0: no free slides)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_flag("--smooth-cabinet-depth", g_smooth_cabinet_depth,
               "the cabinet's depth without disparity quantisation (a smoother sensor)");
  app.add_flag("--kinect-rooms", g_kinect_rooms,
               "the rooms through the cabinet's Kinect-like sensor (disparity steps, holes at "
               "depth edges, depth 2 px off the colour, JPEG colour)");
  app.add_option("--brightness-gain-sigma", g_brightness_gain_sigma,
                 "the depth path fits frame 2's brightness as a gain and an offset of frame 1's, "
                 "the gain with this prior 1-sigma (0: the offset alone)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--exposure-gain", g_exposure_gain,
                 "frame 2's colour times this, saturating (an auto-exposure change; 1: none)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--motion-blur", g_motion_blur_px,
                 "frame 2's colour smeared over this many pixels along its rows (0: none)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--resize", g_resize,
                 "every pair scaled by this factor first (its images and the intrinsics): the "
                 "same scenes as a sensor of another resolution sees them")
      ->check(CLI::Range(0.25, 4.0))
      ->capture_default_str();
  app.add_option("--sensor", g_sensor, pnpba::bench::kSensorHelp)
      ->check(CLI::IsMember(pnpba::bench::kSensorNames))
      ->capture_default_str();
  app.add_option("--axis", g_axis, pnpba::bench::kSweepAxisHelp)
      ->check(CLI::IsMember(pnpba::bench::kSweepAxisNames))
      ->capture_default_str();
  app.add_option("--calibration-error", g_calibration_error,
                 "exact: the estimate is given the renderer's camera; drawn: one seeded draw per "
                 "pair of a calibration with 1-sigma 0.5 % in fx and fy, 1 px in cx and cy, 1 % in "
                 "the depth scale (the covariance model's defaults), the same for every method")
      ->check(CLI::IsMember({"exact", "drawn"}))
      ->capture_default_str();
  app.add_option("--depth-noise", g_depth_noise,
                 "every scene's depth noise k of sigma_z = k z^2 (1/m; 0: the sweep's, 0.0015 "
                 "in the rooms and 0.0025 for the cabinet)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--match-filter", g_match_filter, "ratio, cross-check or textbook (pnpba's)")
      ->check(CLI::IsMember({"ratio", "cross-check", "textbook"}))
      ->capture_default_str();
  app.add_option("--features", g_features, "ORB features for pnpba and OpenCV")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  pnpba::bench::checkOutputPaths({json_path, plot_path});
  g_registration.method = pnpba::parseGlobalRegistration(global_text);

  std::vector<std::string> methods;
  {
    std::stringstream in(methods_text);
    for (std::string m; std::getline(in, m, ',');) methods.push_back(m);
  }
  const std::vector<double> rotations = parseList(rotations_text, "--rotations");
  const std::vector<double> translations = parseList(translations_text, "--translations");
  const pnpba::SyntheticCamera sensor = pnpba::bench::sensorCamera(g_sensor);
  const pnpba::Camera camera = pnpba::bench::estimationCamera(sensor);
  nlohmann::json cells = nlohmann::json::array();
  std::printf("%-5s %5s %5s %-8s %5s %4s %7s %5s %8s\n", "tex", "deg", "m", "method", "pairs", "ok",
              "refused", "wrong", "med_ms");
  std::vector<pnpba::bench::SweepScene> scenes;
  {
    std::stringstream in(scenes_text);
    for (std::string name; std::getline(in, name, ',');) {
      bool known = false;
      for (auto scene : {pnpba::bench::SweepScene::kRich, pnpba::bench::SweepScene::kPoor,
                         pnpba::bench::SweepScene::kCabinet, pnpba::bench::SweepScene::kTiled,
                         pnpba::bench::SweepScene::kStructure, pnpba::bench::SweepScene::kCorridor,
                         pnpba::bench::SweepScene::kPoster}) {
        if (name == pnpba::bench::toString(scene)) scenes.push_back(scene), known = true;
      }
      if (!known) {
        std::fprintf(stderr, "wide_baseline_bench: unknown scene '%s'\n", name.c_str());
        return 2;
      }
    }
  }
  // The registration's plugin opens before timing, as in latency_bench: once per process.
  pnpba::preloadDepthRegistration();
  for (const pnpba::bench::SweepScene scene : scenes) {
    const char* texture = pnpba::bench::toString(scene);
    std::map<std::string, Cell> scene_total;
    std::map<std::string, std::vector<double>> scene_times;
    int skipped = 0;  // pairs whose camera saw no depth (bothViewsHaveDepth)
    std::vector<SweepPoint> points;
    for (double deg : rotations) {
      for (double metres : translations) {
        for (int s = 0; s < seeds; ++s) points.push_back({deg, metres, s});
      }
    }
    // Pairs are rendered before any of them is timed, a batch at a time (at most about
    // kBatchBytes of images): rendering between two estimates (tens of ms on both cores, over
    // memory of its own) slowed the next estimate by a third to a half (docs/benchmarks.md).
    // --render-each renders each just before its methods, the order before.
    std::map<std::pair<double, double>, CellRuns> runs;
    for (size_t next = 0; next < points.size();) {
      std::vector<PreparedPair> batch;
      size_t batch_bytes = 0;
      while (next < points.size() &&
             (batch.empty() || (!g_render_each && batch_bytes < kBatchBytes))) {
        const SweepPoint& at = points[next++];
        std::optional<PreparedPair> prepared = preparePair(scene, at, sensor, camera);
        if (!prepared) {
          std::fprintf(stderr,
                       "wide_baseline_bench: %s %.0f deg %.2f m seed %d: a view without depth "
                       "(the camera turned away from the scene): left out\n",
                       texture, at.deg, at.metres, at.seed);
          ++skipped;
          continue;
        }
        batch_bytes += imageBytes(prepared->pair);
        batch.push_back(std::move(*prepared));
      }
      for (const PreparedPair& prepared : batch) {
        const SweepPoint& at = prepared.at;
        CellRuns& cell = runs[{at.deg, at.metres}];
        for (const std::string& m : methods) {
          const Outcome out = run(m, prepared.pair, prepared.camera);
          Cell& c = cell.counts[m];
          ++c.pairs;
          cell.times[m].push_back(out.time_ms);
          if (!out.returned) {
            if (g_verbose) {
              std::printf("   %s %.0f %.2f s%d %s: refused  %s\n", texture, at.deg, at.metres,
                          at.seed, m.c_str(), out.detail.c_str());
            }
            ++c.refused;
            continue;
          }
          const pnpba::PoseError e = pnpba::relativePoseError(out.T, prepared.pair.T_21);
          if (g_verbose) {
            std::printf("   %s %.0f %.2f s%d %s: %.2f deg %.1f cm  %s\n", texture, at.deg,
                        at.metres, at.seed, m.c_str(), e.rot_deg, e.trans_cm, out.detail.c_str());
          }
          if (e.rot_deg <= 2.0 && e.trans_cm <= 5.0) ++c.ok;
          if (e.rot_deg > 10.0 || e.trans_cm > 50.0) ++c.wrong;
        }
      }
      if (next < points.size()) {
        std::fprintf(stderr, "wide_baseline_bench: %s: %zu of %zu pairs done\n", texture, next,
                     points.size());
      }
    }
    for (double deg : rotations) {
      for (double metres : translations) {
        CellRuns& cell = runs[{deg, metres}];
        for (const std::string& m : methods) {
          const Cell& c = cell.counts[m];
          std::vector<double>& t = cell.times[m];
          if (t.empty()) continue;  // every pair of the cell left out
          std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
          Cell& total = scene_total[m];
          total.pairs += c.pairs, total.ok += c.ok, total.refused += c.refused;
          total.wrong += c.wrong;
          scene_times[m].insert(scene_times[m].end(), t.begin(), t.end());
          std::printf("%-5s %5.0f %5.2f %-8s %5d %4d %7d %5d %8.1f\n", texture, deg, metres,
                      m.c_str(), c.pairs, c.ok, c.refused, c.wrong, t[t.size() / 2]);
          std::fflush(stdout);
          cells.push_back({{"rotation_deg", deg},
                           {"translation_m", metres},
                           {"scene", texture},
                           {"method", m},
                           {"pairs", c.pairs},
                           {"ok", c.ok},
                           {"refused", c.refused},
                           {"wrong", c.wrong},
                           {"median_ms", t[t.size() / 2]}});
        }
      }
    }
    // The scene over every cell: the counts and the pairs' time, its median, 95th percentile
    // (latency_bench's: the sorted times' element p (n - 1), rounded) and maximum.
    for (const std::string& m : methods) {
      const Cell& c = scene_total[m];
      std::vector<double>& t = scene_times[m];
      if (t.empty()) continue;
      std::sort(t.begin(), t.end());
      auto rank = [&t](double q) {
        return t[std::min(t.size() - 1, static_cast<size_t>(q * (t.size() - 1) + 0.5))];
      };
      std::printf("%-5s   all  all %-8s %5d %4d %7d %5d   p50 %.1f p95 %.1f max %.1f ms", texture,
                  m.c_str(), c.pairs, c.ok, c.refused, c.wrong, rank(0.5), rank(0.95), t.back());
      if (skipped > 0) {
        std::printf("  (%d %s left out: a view without depth)", skipped,
                    skipped == 1 ? "pair" : "pairs");
      }
      std::printf("\n");
    }
  }
  if (!plot_path.empty()) writePlot(plot_path, cells, methods, rotations, translations);
  if (!json_path.empty()) {
    pnpba::bench::writeJsonFile(json_path, {{"cells", cells}}, 1);
  }
  return 0;
}

int main(int argc, char** argv) {
  return pnpba::bench::guardedMain("wide_baseline_bench", benchMain, argc, argv);
}
