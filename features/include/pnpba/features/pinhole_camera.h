// PinholeCamera: intrinsics and OpenCV's 5-coefficient distortion (k1 k2 p1 p2 k3).
// Pixels: u = fx x/z + cx, v = fy y/z + cy on undistorted normalised coordinates. fx > 0; fy
// may be negative (image rows running upwards, as in ICL-NUIM).
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>

namespace pnpba {

struct PinholeCamera {
  double fx = 520.9, fy = 521.0, cx = 325.1, cy = 249.7;  // the textbook pair's camera
  std::array<double, 5> distortion{};                     // k1 k2 p1 p2 k3

  bool hasDistortion() const;
  // Empty when valid, else e.g. "fx must be finite and > 0".
  std::string validate() const;
  Eigen::Vector2d project(const Eigen::Vector3d& P) const {
    return {fx * P.x() / P.z() + cx, fy * P.y() / P.z() + cy};
  }
  // The point at depth z seen at undistorted pixel uv.
  Eigen::Vector3d backProject(const Eigen::Vector2d& uv, double z) const {
    return {(uv.x() - cx) / fx * z, (uv.y() - cy) / fy * z, z};
  }
};

}  // namespace pnpba
