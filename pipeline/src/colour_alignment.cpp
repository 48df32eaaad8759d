#include "pnpba/pipeline/colour_alignment.h"

#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/ColoredICP.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/utility/Logging.h>

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "depth_cloud.h"
#include "pnpba/core/error.h"

namespace pnpba {

namespace reg = open3d::pipelines::registration;
using open3d::geometry::KDTreeSearchParamHybrid;
using open3d::geometry::PointCloud;

std::string ColourAlignmentOptions::validate() const {
  if (voxels_m.empty()) return "colour alignment: no voxel sizes";
  for (size_t i = 0; i < voxels_m.size(); ++i) {
    if (!(voxels_m[i] > 0) || !std::isfinite(voxels_m[i])) {
      return "colour alignment: voxel sizes must be > 0";
    }
    if (i > 0 && !(voxels_m[i] <= voxels_m[i - 1])) {
      return "colour alignment: voxel sizes must run coarse to fine";
    }
  }
  if (iterations < 1) return "colour alignment: iterations must be >= 1";
  if (!(lambda_geometric >= 0 && lambda_geometric <= 1)) {
    return "colour alignment: lambda_geometric must be in [0, 1]";
  }
  if (pixel_stride < 1) return "colour alignment: pixel stride must be >= 1";
  if (!(max_range_m > 0.1)) return "colour alignment: max range must be > 0.1 m";
  return "";
}

ColourAlignment alignColouredDepths(const cv::Mat& image1, const cv::Mat& depth1,
                                    const cv::Mat& image2, const cv::Mat& depth2,
                                    const PinholeCamera& camera, double depth_scale,
                                    const SE3Quat& T_seed, const ColourAlignmentOptions& o) {
  const std::string problem = o.validate();
  if (!problem.empty()) throw Error(problem);
  if (depth1.type() != CV_16UC1 || depth2.type() != CV_16UC1) {
    throw Error("colour alignment needs two 16-bit single-channel depth images");
  }
  const auto start = std::chrono::steady_clock::now();
  open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Error);
  ColourAlignment r;
  auto finish = [&](const std::string& failure) {
    r.failure = failure;
    r.time_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return r;
  };
  const auto full1 = depthCloud(depth1, camera, depth_scale, o.pixel_stride, o.max_range_m, image1);
  const auto full2 = depthCloud(depth2, camera, depth_scale, o.pixel_stride, o.max_range_m, image2);
  constexpr size_t kMinPoints = 50;
  if (full1->points_.size() < kMinPoints || full2->points_.size() < kMinPoints) {
    return finish("too little depth for the colour alignment");
  }
  Eigen::Matrix4d T = T_seed.to_homogeneous_matrix();
  reg::RegistrationResult result;
  for (double voxel : o.voxels_m) {
    const auto source = full1->VoxelDownSample(voxel);
    const auto target = full2->VoxelDownSample(voxel);
    if (source->points_.size() < kMinPoints || target->points_.size() < kMinPoints) continue;
    target->EstimateNormals(KDTreeSearchParamHybrid(2.0 * voxel, 30));
    target->OrientNormalsTowardsCameraLocation(Eigen::Vector3d::Zero());
    try {
      result = reg::RegistrationColoredICP(
          *source, *target, 1.5 * voxel, T,
          reg::TransformationEstimationForColoredICP(o.lambda_geometric),
          reg::ICPConvergenceCriteria(1e-6, 1e-6, o.iterations));
    } catch (const std::runtime_error&) {
      // Open3D throws when a level finds no correspondence at all: nothing overlaps there.
      return finish("colour alignment found no overlap");
    }
    if (!result.transformation_.allFinite()) return finish("colour alignment diverged");
    // A level without correspondences leaves the pose where it was.
    if (!result.correspondence_set_.empty()) T = result.transformation_;
  }
  if (result.correspondence_set_.size() < kMinPoints) {
    return finish("colour alignment found no overlap");
  }
  r.T_21 = SE3Quat(T.topLeftCorner<3, 3>(), T.topRightCorner<3, 1>());
  r.fitness = result.fitness_;
  r.inlier_rmse = result.inlier_rmse_;
  r.ok = true;
  return finish("");
}

}  // namespace pnpba
