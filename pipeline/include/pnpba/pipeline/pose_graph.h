// Builds the two-view bundle-adjustment graphs of pnpba from 3D-2D pairs, on the optimize
// module's g2o-compatible types. Camera 1 is the world frame; the pose vertex holds T_21.
//
// Vertex ids: 0 = pose of camera 2 (T_21), 1..N = points (marginalised), N+1 = camera 1
// (fixed identity) when the mode has one.
//
//   kPose       motion-only: EdgeSE3ProjectXYZOnlyPose per pair (fx, fy), points fixed.
//   kTextbook   the textbook graph: pose + free points, EdgeProjectXYZ2UV in camera 2 only,
//               single-focal CameraParameters(fx, (cx, cy)). Under-determined: kept for parity.
//   kTwoCamera  kTextbook + camera 1 observing each point at its image-1 pixel.
//   kRgbd       camera 1 observes each point by pixel AND depth (EdgeStereoSE3ProjectXYZ with a
//               virtual baseline), camera 2 by pixel (EdgeSE3ProjectXYZ, fx and fy): the scale
//               is fixed by depth. Depth noise sigma_z = depth_noise_k * z^2.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "pnpba/optimize/se3_quat.h"
#include "pnpba/optimize/sparse_optimizer.h"

namespace pnpba {

struct PointPair {
  Eigen::Vector3d X_1;   // point in camera 1 (from depth 1)
  Eigen::Vector2d uv_2;  // pixel in image 2
  Eigen::Vector2d uv_1;  // pixel in image 1
};

struct Intrinsics {
  double fx = 520.9, fy = 521.0, cx = 325.1, cy = 249.7;
};

enum class BundleMode { kPose, kTextbook, kTwoCamera, kRgbd };
const char* toString(BundleMode mode);
BundleMode parseBundleMode(const std::string& name);  // throws Error

struct PoseGraphOptions {
  BundleMode mode = BundleMode::kRgbd;
  Intrinsics intrinsics;
  double pixel_sigma = 1.0;       // px, image noise of every pixel measurement
  double depth_noise_k = 0.003;   // 1/m: sigma_z = k z^2 (NOTES-accuracy.md: median 0.003)
  double virtual_baseline = 0.1;  // m: the stereo form's baseline; any value gives the same
                                  // cost, this one keeps the disparity near pixel scale
  double huber_delta = 0.0;       // > 0 puts a Huber kernel of this width (sqrt chi2) on
                                  // every edge
  std::string validate() const;
};

// Ids of the vertices the builder created.
struct PoseGraphIds {
  static constexpr int kPose = 0;
  int first_point = 1;
  int camera1 = -1;  // -1 when the mode has no camera-1 vertex
};

// Adds the graph for `pairs` to an empty optimizer, starting from T_21 and the pairs' points.
PoseGraphIds buildPoseGraph(SparseOptimizer& optimizer, const std::vector<PointPair>& pairs,
                            const SE3Quat& T_21, const PoseGraphOptions& options);

}  // namespace pnpba
