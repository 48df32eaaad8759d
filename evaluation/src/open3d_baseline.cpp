#include "pnpba/evaluation/open3d_baseline.h"

#include <chrono>
#include <cmath>

#include "open3d_odometry_api.h"
#include "pnpba/core/error.h"
#include "pnpba/core/plugin.h"

namespace pnpba {

std::string Open3dOdometryOptions::validate() const {
  if (!(min_depth >= 0) || !(max_depth > min_depth) || std::isinf(max_depth)) {
    return "Open3D odometry: depth range must satisfy 0 <= min < max < inf";
  }
  return "";
}

TwoViewResult estimateTwoViewOpen3dOdometry(const cv::Mat& image1, const cv::Mat& depth1,
                                            const cv::Mat& image2, const cv::Mat& depth2,
                                            const Camera& camera,
                                            const Open3dOdometryOptions& options) {
  if (const std::string problem = options.validate(); !problem.empty()) throw Error(problem);
  if (const std::string problem = camera.validate(); !problem.empty()) throw Error(problem);
  if (depth2.empty()) throw Error("depth 2: Open3D's RGB-D odometry needs both depth images");
  checkTwoViewInputs(image1, depth1, image2, depth2);
  static auto* const odometry =
      pluginFunction<Open3dRgbdOdometry>(kOpen3dOdometryPlugin, kOpen3dOdometrySymbol);
  const auto start = std::chrono::steady_clock::now();
  const double intrinsics[4] = {camera.pinhole.fx, camera.pinhole.fy, camera.pinhole.cx,
                                camera.pinhole.cy};
  bool ok = false;
  double T[16] = {};
  char message[kOpen3dOdometryMessageSize];
  odometry(&image1, &depth1, &image2, &depth2, intrinsics, camera.depth_scale, options.min_depth,
           options.max_depth, &ok, T, message);
  TwoViewResult r;
  r.times_ms.total_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  r.solver = "open3d-odometry";
  const Eigen::Matrix4d M = Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(T);
  if (message[0] != '\0') throw Error(std::string("Open3D's RGB-D odometry: ") + message);
  if (!ok || !M.allFinite()) {
    r.failure = "Open3D's RGB-D odometry reported failure";
    return r;
  }
  r.T_21 = r.T_init = SE3Quat(Eigen::Matrix3d(M.topLeftCorner<3, 3>()), M.topRightCorner<3, 1>());
  r.ok = true;
  return r;
}

}  // namespace pnpba
