// The bench-only plugin behind open3d_odometry_anchor.h: Open3D's RGB-D odometry as a user
// calls it, from the identity, with Open3D's default options but the depth range pnpba uses.
#include "open3d_odometry_anchor.h"

#include <open3d/camera/PinholeCameraIntrinsic.h>
#include <open3d/geometry/Image.h>
#include <open3d/geometry/RGBDImage.h>
#include <open3d/pipelines/odometry/Odometry.h>
#include <open3d/utility/Logging.h>

#include <chrono>
#include <cstring>
#include <opencv2/imgproc.hpp>
#include <type_traits>

namespace {

open3d::geometry::Image toOpen3d(const cv::Mat& m) {
  open3d::geometry::Image image;
  image.Prepare(m.cols, m.rows, m.channels(), static_cast<int>(m.elemSize1()));
  const size_t row_bytes = m.cols * m.elemSize();
  for (int y = 0; y < m.rows; ++y) {
    std::memcpy(image.data_.data() + y * row_bytes, m.ptr(y), row_bytes);
  }
  return image;
}

std::shared_ptr<open3d::geometry::RGBDImage> rgbd(const cv::Mat& colour, const cv::Mat& depth,
                                                  double depth_scale, double max_depth_m) {
  cv::Mat rgb;
  if (colour.channels() == 1) {
    cv::cvtColor(colour, rgb, cv::COLOR_GRAY2RGB);
  } else {
    cv::cvtColor(colour, rgb, cv::COLOR_BGR2RGB);
  }
  return open3d::geometry::RGBDImage::CreateFromColorAndDepth(
      toOpen3d(rgb), toOpen3d(depth), depth_scale, max_depth_m, /*convert_rgb_to_intensity=*/true);
}

}  // namespace

extern "C" __attribute__((visibility("default"))) void pnpba_bench_open3d_odometry(
    const cv::Mat* image1, const cv::Mat* depth1, const cv::Mat* image2, const cv::Mat* depth2,
    const pnpba::Camera* camera, double min_depth_m, double max_depth_m,
    pnpba::bench::OdometryAnchor* out) {
  static_assert(
      std::is_same_v<decltype(pnpba_bench_open3d_odometry), pnpba::bench::Open3dOdometry>);
  const auto start = std::chrono::steady_clock::now();
  *out = {};
  // Open3D warns on stdout about every pair with too few correspondences; the result says so.
  open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Error);
  const auto source = rgbd(*image1, *depth1, camera->depth_scale, max_depth_m);
  const auto target = rgbd(*image2, *depth2, camera->depth_scale, max_depth_m);
  const open3d::camera::PinholeCameraIntrinsic intrinsic(image1->cols, image1->rows,
                                                         camera->pinhole.fx, camera->pinhole.fy,
                                                         camera->pinhole.cx, camera->pinhole.cy);
  open3d::pipelines::odometry::OdometryOption option;
  option.depth_min_ = min_depth_m;
  option.depth_max_ = max_depth_m;
  // The transformation maps the source's points into the target's frame: X2 = T X1.
  const auto [ok, T, information] = open3d::pipelines::odometry::ComputeRGBDOdometry(
      *source, *target, intrinsic, Eigen::Matrix4d::Identity(),
      open3d::pipelines::odometry::RGBDOdometryJacobianFromHybridTerm(), option);
  (void)information;
  out->ok = ok;
  out->T_21 = pnpba::SE3Quat(Eigen::Matrix3d(T.topLeftCorner<3, 3>()), T.topRightCorner<3, 1>());
  out->ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}
