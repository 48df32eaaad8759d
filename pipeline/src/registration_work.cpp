#include "registration_work.h"

#include <algorithm>
#include <vector>

#include "rgbd_residuals.h"  // medianInPlace

namespace pnpba {

namespace {

constexpr int kStride = 8;

// The surface area (m^2) a depth image sees facing the camera, and its depths (m), on every
// kStride-th pixel. A slanted floor or wall holds more of the grid's voxels than its footprint
// says, and a noisy one more again; a learned rate per point absorbs that, and it varied less
// from scene to scene with the footprint alone (the rendered rooms and the real cabinet, 8-12 ms
// per thousand predicted points) than with each patch's slant measured (4.3-7.8).
double surfaceArea(const cv::Mat& depth, const PinholeCamera& camera, double depth_scale,
                   double max_range_m, std::vector<double>* depths) {
  double sum_z2 = 0;
  for (int v = 0; v < depth.rows; v += kStride) {
    const uint16_t* row = depth.ptr<uint16_t>(v);
    for (int u = 0; u < depth.cols; u += kStride) {
      const double z = row[u] / depth_scale;
      if (!(z > 0) || z > max_range_m) continue;
      sum_z2 += z * z;
      if (depths != nullptr) depths->push_back(z);
    }
  }
  return sum_z2 * kStride * kStride / (camera.fx * camera.fy);
}

}  // namespace

double predictedRegistrationKilopoints(const cv::Mat& depth1, const cv::Mat& depth2,
                                       const PinholeCamera& camera, double depth_scale,
                                       const DepthRegistrationOptions& options) {
  std::vector<double> z1;
  const double area1 = surfaceArea(depth1, camera, depth_scale, options.max_range_m, &z1);
  const double area2 = surfaceArea(depth2, camera, depth_scale, options.max_range_m, nullptr);
  if (z1.empty()) return 0;
  double voxel = options.voxel_m;
  if (options.voxel_depth_fraction > 0) {
    voxel = std::min(voxel, options.voxel_depth_fraction * medianInPlace(&z1));
  }
  double points1 = area1 / (voxel * voxel), points2 = area2 / (voxel * voxel);
  if (options.max_points > 0 && points1 > options.max_points) {
    points2 *= options.max_points / points1;
    points1 = options.max_points;
  }
  return (points1 + points2) / 1000;
}

}  // namespace pnpba
