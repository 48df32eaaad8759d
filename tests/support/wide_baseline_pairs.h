// The wide-baseline sweep's rendered pairs, shared by the benches and tests that use them:
// the closed room with rich or poor texture, camera 2 turned `deg` about a random near-vertical
// axis (or, asked for, one near camera 1's x axis or its optical axis) and moved `metres` while
// looking at the room (SyntheticScene::lookAtMotion), one seed per index.
#pragma once

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "pnpba/core/error.h"
#include "pnpba/pipeline/camera.h"
#include "pnpba/synthetic/synthetic_pair.h"
#include "pnpba/synthetic/synthetic_scene.h"

namespace pnpba::bench {

// The sweep's scenes: the closed room with rich or poor texture, and the plain cabinet by a wall
// seen through a Kinect-like sensor with JPEG colour (SensorEffects::kinectLike). Beside them,
// not in the default sweep: the closed room with the rich texture tiled (SceneTexture::kTiled),
// where the features' wrong matches agree with one another, and the plain zig-zag structure
// (SceneLayout::kStructure) through the cabinet's sensor, whose geometry repeats, and the plain
// wall on a plain floor (SceneLayout::kCorridor), the same sensor, along which a slide is free,
// and a rich poster on a plain wall (SceneLayout::kPoster), the same sensor: one plane.
enum class SweepScene { kRich, kPoor, kCabinet, kTiled, kStructure, kCorridor, kPoster };
const char* toString(SweepScene scene);

// The axis camera 2 turns about, each within 23 degrees (a random jitter per seed): pan, the
// sweep's own (near camera 1's vertical y axis: a robot or a person turning); tilt (near its x
// axis: looking up or down); roll (near its optical axis: a hand-held camera or an arm turning
// the view).
enum class SweepAxis { kPan, kTilt, kRoll };
inline const std::vector<std::string> kSweepAxisNames = {"pan", "tilt", "roll"};
inline SweepAxis parseSweepAxis(const std::string& name) {
  for (size_t i = 0; i < kSweepAxisNames.size(); ++i) {
    if (name == kSweepAxisNames[i]) return static_cast<SweepAxis>(i);
  }
  throw Error("unknown axis '" + name + "' (pan, tilt, roll)");
}
constexpr const char* kSweepAxisHelp =
    "what camera 2 turns about, within 23 degrees: pan (near camera 1's vertical axis, the "
    "sweep's own), tilt (near its x axis: looking up or down) or roll (near its optical axis)";

inline SyntheticPairOptions wideBaselinePair(SweepScene scene, double deg, double metres,
                                             int seed_index, SweepAxis turn = SweepAxis::kPan) {
  const unsigned seed = 1000 + 97 * seed_index + static_cast<unsigned>(deg * 7 + metres * 100);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  // The pan axis as the sweep has always drawn it; the others take its components in turn, so
  // that every axis sees the same seeds' jitter.
  const Eigen::Vector3d pan(jitter(rng), rng() % 2 ? 1.0 : -1.0, jitter(rng));
  const Eigen::Vector3d axis = turn == SweepAxis::kTilt ? Eigen::Vector3d(pan.y(), pan.x(), pan.z())
                               : turn == SweepAxis::kRoll
                                   ? Eigen::Vector3d(pan.x(), pan.z(), pan.y())
                                   : pan;
  SyntheticPairOptions o;
  o.seed = seed;
  o.layout = scene == SweepScene::kCabinet     ? SceneLayout::kCabinet
             : scene == SweepScene::kStructure ? SceneLayout::kStructure
             : scene == SweepScene::kCorridor  ? SceneLayout::kCorridor
             : scene == SweepScene::kPoster    ? SceneLayout::kPoster
                                               : SceneLayout::kClosedRoom;
  o.texture = scene == SweepScene::kRich || scene == SweepScene::kPoster ? SceneTexture::kRich
              : scene == SweepScene::kTiled                              ? SceneTexture::kTiled
                                                                         : SceneTexture::kPoor;
  if (scene == SweepScene::kCabinet || scene == SweepScene::kStructure ||
      scene == SweepScene::kCorridor || scene == SweepScene::kPoster) {
    o.sensor = SensorEffects::kinectLike();
    o.noise.noise_k = 0.0025;  // Kinect-like: about 1 cm at 2 m before quantisation
  }
  o.noise.max_range = 8.0;
  o.T_21 = SyntheticScene::lookAtMotion(deg, axis, metres);
  return o;
}

// Whether both rendered views hold depth. A camera turned away from the scene (tilted up past the
// cabinet scene's open top) sees none, and the two-view pose takes an all-zero depth image as an
// input error: the benches leave such a pair out and say so.
inline bool bothViewsHaveDepth(const SyntheticPair& p) {
  return cv::countNonZero(p.view1.depth) > 0 && cv::countNonZero(p.view2.depth) > 0;
}

// The camera the sweep is rendered through: tum, the textbook's (640 x 480, depth x5000), or
// another sensor's size and field of view, principal point at the centre, depth x1000 (mm) as
// RealSense and Azure Kinect write it: realsense (848 x 480, D435-like colour, 90 x 59 degrees)
// or azure (1280 x 720, Azure Kinect-like colour, 93 x 61 degrees). Throws Error for another name.
inline SyntheticCamera sensorCamera(const std::string& name) {
  SyntheticCamera c;
  if (name == "tum") return c;
  auto wide = [&c](int width, int height, double f) {
    c.width = width, c.height = height;
    c.pinhole.fx = c.pinhole.fy = f;
    c.pinhole.cx = (width - 1) / 2.0, c.pinhole.cy = (height - 1) / 2.0;
    c.depth_scale = 1000.0;
  };
  if (name == "realsense") {
    wide(848, 480, 425.0);
  } else if (name == "azure") {
    wide(1280, 720, 610.0);
  } else if (name == "azure-1080p") {
    wide(1920, 1080, 915.0);  // the same field of view at 1.5 times the pixels a side
  } else {
    throw Error("unknown sensor '" + name + "' (tum, realsense, azure, azure-1080p)");
  }
  return c;
}

// The benches' --sensor option: what sensorCamera knows.
inline const std::vector<std::string> kSensorNames = {"tum", "realsense", "azure", "azure-1080p"};
constexpr const char* kSensorHelp =
    "the camera the sweep is rendered through: tum (640 x 480, the textbook's intrinsics, depth "
    "x5000), realsense (848 x 480, 90 degrees wide, depth x1000), azure (1280 x 720, 93 degrees "
    "wide, depth x1000) or azure-1080p (the same at 1920 x 1080)";

// The camera the two-view pose is given for pairs rendered through `c`.
inline Camera estimationCamera(const SyntheticCamera& c) {
  Camera camera;
  camera.pinhole = c.pinhole;
  camera.depth_scale = c.depth_scale;
  camera.width = c.width, camera.height = c.height;
  return camera;
}

// A calibrated sensor's camera: `camera` off by one draw of a calibration with these 1-sigmas
// (fx and fy each relative, cx and cy each in pixels, the depth scale relative), seeded by the
// sweep cell so that every condition and method of a cell sees the same error.
struct CalibrationSigmas {
  double focal = 0.005, principal_point_px = 1.0, depth_scale = 0.005;
};
inline void drawCalibrationError(const CalibrationSigmas& sigma, SweepScene scene, double deg,
                                 double metres, int seed_index, Camera* camera) {
  std::mt19937 rng(1000003u * static_cast<unsigned>(scene) + 10007u * static_cast<unsigned>(deg) +
                   101u * static_cast<unsigned>(std::lround(metres * 100)) +
                   static_cast<unsigned>(seed_index));
  std::normal_distribution<double> unit(0.0, 1.0);
  camera->pinhole.fx *= 1 + sigma.focal * unit(rng);
  camera->pinhole.fy *= 1 + sigma.focal * unit(rng);
  camera->pinhole.cx += sigma.principal_point_px * unit(rng);
  camera->pinhole.cy += sigma.principal_point_px * unit(rng);
  camera->depth_scale *= 1 + sigma.depth_scale * unit(rng);
}

inline const char* toString(SweepScene scene) {
  switch (scene) {
    case SweepScene::kRich:
      return "rich";
    case SweepScene::kPoor:
      return "poor";
    case SweepScene::kCabinet:
      return "cabinet";
    case SweepScene::kTiled:
      return "tiled";
    case SweepScene::kStructure:
      return "structure";
    case SweepScene::kCorridor:
      return "corridor";
    case SweepScene::kPoster:
      return "poster";
  }
  return "?";
}

}  // namespace pnpba::bench
