// The plugin behind open3d_baseline.h: Open3D's RGB-D odometry as a user calls it, from the
// identity, with Open3D's default options but the depth range pnpba uses.
#include <open3d/camera/PinholeCameraIntrinsic.h>
#include <open3d/geometry/Image.h>
#include <open3d/geometry/RGBDImage.h>
#include <open3d/pipelines/odometry/Odometry.h>
#include <open3d/utility/Logging.h>

#include <cstdio>
#include <cstring>
#include <exception>
#include <opencv2/imgproc.hpp>
#include <type_traits>

#include "../src/open3d_odometry_api.h"

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

// Open3D wants RGB (it weighs the channels into intensity); OpenCV reads BGR.
std::shared_ptr<open3d::geometry::RGBDImage> rgbd(const cv::Mat& colour, const cv::Mat& depth,
                                                  double depth_scale, double max_depth_m) {
  cv::Mat rgb;
  cv::cvtColor(colour, rgb, colour.channels() == 1 ? cv::COLOR_GRAY2RGB : cv::COLOR_BGR2RGB);
  return open3d::geometry::RGBDImage::CreateFromColorAndDepth(
      toOpen3d(rgb), toOpen3d(depth), depth_scale, max_depth_m, /*convert_rgb_to_intensity=*/true);
}

}  // namespace

extern "C" __attribute__((visibility("default"))) void pnpba_open3d_rgbd_odometry(
    const cv::Mat* image1, const cv::Mat* depth1, const cv::Mat* image2, const cv::Mat* depth2,
    const double intrinsics[4], double depth_scale, double min_depth_m, double max_depth_m,
    bool* ok, double T_21[16], char message[pnpba::kOpen3dOdometryMessageSize]) {
  static_assert(std::is_same_v<decltype(pnpba_open3d_rgbd_odometry), pnpba::Open3dRgbdOdometry>);
  *ok = false;
  message[0] = '\0';
  try {
    // Open3D warns on stdout about a pair with too few correspondences; the flag says so.
    open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Error);
    const auto source = rgbd(*image1, *depth1, depth_scale, max_depth_m);
    const auto target = rgbd(*image2, *depth2, depth_scale, max_depth_m);
    const open3d::camera::PinholeCameraIntrinsic camera(
        image1->cols, image1->rows, intrinsics[0], intrinsics[1], intrinsics[2], intrinsics[3]);
    open3d::pipelines::odometry::OdometryOption option;
    option.depth_min_ = min_depth_m;
    option.depth_max_ = max_depth_m;
    // The transformation maps the source's points into the target's frame: X2 = T X1.
    const auto [success, T, information] = open3d::pipelines::odometry::ComputeRGBDOdometry(
        *source, *target, camera, Eigen::Matrix4d::Identity(),
        open3d::pipelines::odometry::RGBDOdometryJacobianFromHybridTerm(), option);
    (void)information;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) T_21[4 * r + c] = T(r, c);
    }
    *ok = success;
  } catch (const std::exception& e) {
    std::snprintf(message, pnpba::kOpen3dOdometryMessageSize, "%s", e.what());
  }
}
