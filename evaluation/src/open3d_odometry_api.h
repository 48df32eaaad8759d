// The function the evaluation's Open3D plugin (evaluation/plugin/open3d_odometry.cpp) exports
// and open3d_baseline.cpp calls: plain types only, so that the plugin links nothing of pnpba's.
// It does not throw: what Open3D throws comes back as `message`.
#pragma once

#include <opencv2/core.hpp>

namespace pnpba {

inline constexpr const char* kOpen3dOdometryPlugin = "open3d_odometry";
inline constexpr const char* kOpen3dOdometrySymbol = "pnpba_open3d_rgbd_odometry";

// intrinsics: fx, fy, cx, cy; depth_scale: depth values per metre. On return *ok is Open3D's
// success flag and T_21 the 4 x 4 row-major transformation (X2 = T X1); message is empty, or
// what Open3D threw (then *ok is false).
inline constexpr size_t kOpen3dOdometryMessageSize = 256;
using Open3dRgbdOdometry = void(const cv::Mat* image1, const cv::Mat* depth1, const cv::Mat* image2,
                                const cv::Mat* depth2, const double intrinsics[4],
                                double depth_scale, double min_depth_m, double max_depth_m,
                                bool* ok, double T_21[16],
                                char message[kOpen3dOdometryMessageSize]);

}  // namespace pnpba
