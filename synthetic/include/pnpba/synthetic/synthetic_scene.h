// A deterministic synthetic RGB-D scene with exact ground truth: a room-like set of textured
// rectangles (floor, walls, boxes) with texture rich enough for ORB, rendered by ray casting
// through a pinhole camera with optional OpenCV distortion, and a Kinect-like depth image
// (16-bit, value = z * depth_scale, noise sigma_z = noise_k z^2, holes).
// World frame = camera 1 frame; poses are T_cw (world -> camera).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pnpba/features/pinhole_camera.h"
#include "pnpba/optimize/se3_quat.h"

namespace pnpba {

// The rendering camera: pinhole with optional distortion, image size, depth units per metre.
struct SyntheticCamera {
  PinholeCamera pinhole;        // defaults: the textbook pair (520.9, 521.0, 325.1, 249.7)
  int width = 640, height = 480;
  double depth_scale = 5000.0;  // depth value per metre (TUM 5000, others 1000)
};

struct DepthNoise {
  double noise_k = 0.0015;      // 1/m: sigma_z = k z^2
  double hole_fraction = 0.02;  // pixels dropped at random (value 0)
  double max_range = 6.0;       // m: farther is 0, as a sensor reports
};

struct RenderedView {
  cv::Mat colour;  // CV_8UC3
  cv::Mat depth;   // CV_16UC1
};

class SyntheticScene {
 public:
  explicit SyntheticScene(unsigned seed = 7);

  // Renders the scene from pose T_cw with `camera` (its distortion applied to the image).
  RenderedView render(const SyntheticCamera& camera, const SE3Quat& T_cw, const DepthNoise& noise,
                      unsigned noise_seed) const;

  // The textbook-like pair: camera 1 at the origin, camera 2 moved by about 3 degrees and
  // 12 cm. Returns T_21.
  static SE3Quat defaultMotion();

 private:
  struct Quad {
    Eigen::Vector3d origin, axis_u, axis_v;  // point = origin + s u + t v, s,t in [0, 1]
    int texture = 0;
  };
  // Nearest hit along the ray: depth parameter and colour; false if none.
  bool castRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double* distance,
               cv::Vec3b* colour) const;

  std::vector<Quad> quads_;
  std::vector<cv::Mat> textures_;  // CV_8UC3
};

}  // namespace pnpba
