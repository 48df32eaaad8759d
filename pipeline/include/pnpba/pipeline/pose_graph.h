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
//               virtual baseline), camera 2 by pixel (EdgeSE3ProjectXYZ, fx and fy), or by
//               pixel and depth when the pair has a depth 2 consistent with the start pose
//               (chi2 <= depth2_gate_chi2): the scale is fixed by depth. Depth noise
//               sigma_z = depth_noise_k * z^2.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "pnpba/features/pinhole_camera.h"
#include "pnpba/optimize/rgbd_pair.h"
#include "pnpba/optimize/se3_quat.h"
#include "pnpba/optimize/sparse_optimizer.h"

namespace pnpba {

struct PointPair {
  Eigen::Vector3d X_1;                                        // point in camera 1 (from depth 1)
  Eigen::Vector2d uv_2;                                       // pixel in image 2
  Eigen::Vector2d uv_1;                                       // pixel in image 1
  double depth_2 = std::numeric_limits<double>::quiet_NaN();  // depth 2 at uv_2 (m), if any
  // Relative pixel noise of each observation, multiplying PoseGraphOptions::pixel_sigma:
  // ORB keypoints of pyramid level l are localised to about scale_factor^l pixels.
  double sigma_2 = 1.0, sigma_1 = 1.0;
};

// kNone (no refinement) is for the pipeline; buildPoseGraph rejects it.
enum class BundleMode { kNone, kPose, kTextbook, kTwoCamera, kRgbd };
const char* toString(BundleMode mode);
BundleMode parseBundleMode(const std::string& name);  // throws Error

struct PoseGraphOptions {
  BundleMode mode = BundleMode::kRgbd;
  PinholeCamera intrinsics;       // distortion unused: pixels are already undistorted
  double pixel_sigma = 1.0;       // px, image noise of every pixel measurement
  double depth_noise_k = 0.003;   // 1/m: sigma_z = k z^2 (NOTES-accuracy.md: median 0.003)
  double virtual_baseline = 0.1;  // m: the stereo form's baseline; any value gives the same
                                  // cost, this one keeps the disparity near pixel scale
  // Huber kernel on every edge, of width sqrt(chi2 95% quantile) for the edge's dimension
  // (5.991 for pixels, 7.815 for pixel + depth), ORB-SLAM's choice.
  bool robust = false;
  // Depth-2 observations whose chi2 at the start pose exceeds this are left out (NOTES:
  // ungated, inconsistent depth-2 values stall the solve).
  double depth2_gate_chi2 = 9.0;
  std::string validate() const;
};

// Ids of the vertices the builder created.
struct PoseGraphIds {
  static constexpr int kPose = 0;
  int first_point = 1;
  int camera1 = -1;          // -1 when the mode has no camera-1 vertex
  std::vector<char> depth2;  // kRgbd: per pair, whether camera 2's edge carries depth 2
};

// Adds the graph for `pairs` to an empty optimizer, starting from T_21 and the pairs' points.
PoseGraphIds buildPoseGraph(SparseOptimizer& optimizer, const std::vector<PointPair>& pairs,
                            const SE3Quat& T_21, const PoseGraphOptions& options);

// The kRgbd graph of buildPoseGraph as arrays for the dedicated solver
// (pnpba/optimize/rgbd_pair.h): the same measurements, informations, kernels and depth-2 gate;
// *depth2 flags, per pair, whether camera 2's observation carries depth 2. options.mode must be
// kRgbd.
RgbdPairProblem rgbdPairProblem(const std::vector<PointPair>& pairs, const SE3Quat& T_21,
                                const PoseGraphOptions& options, std::vector<char>* depth2);

// The kRgbd graph's marginal pose covariance at T_21 with every point at its X_1, camera 2's
// edge carrying depth 2 where `depth2` flags it (per pair), without robust kernels, once for
// each depth noise k in `depth_noise_k` (options.depth_noise_k unused): the information with the
// points eliminated, in closed form and one pass over the points (what
// SparseOptimizer::computeMarginalCovariance gives for each such graph). The covariance model
// evaluates it at other noise levels than the solve's. False when one is singular.
bool rgbdPoseCovariances(const std::vector<PointPair>& pairs, const std::vector<char>& depth2,
                         const SE3Quat& T_21, const PoseGraphOptions& options,
                         const std::vector<double>& depth_noise_k,
                         std::vector<Eigen::Matrix<double, 6, 6>>* covariances);

}  // namespace pnpba
