// Open3D's RGB-D odometry as a user calls it, for side-by-side evaluation:
// open3d::pipelines::odometry::ComputeRGBDOdometry with the hybrid (photometric + geometric)
// term, from the identity, Open3D's default iterations per level ({20, 10, 5}) and depth
// difference (3 cm), and the depth range pnpba's depth lookup uses. Its images are the
// sensor's, undistorted by nothing (Open3D's odometry has no distortion model). It lives in a
// plugin (libpnpba_open3d_odometry.so, pnpba/core/plugin.h) opened on the first call, so that a
// program that never calls it loads no Open3D.
#pragma once

#include <opencv2/core.hpp>

#include "pnpba/features/depth_lookup.h"
#include "pnpba/pipeline/two_view.h"

namespace pnpba {

// Depths outside [min_depth, max_depth] (m) are ignored; by default pnpba's depth lookup's range.
struct Open3dOdometryOptions {
  double min_depth = DepthOptions{}.min_depth;
  double max_depth = DepthOptions{}.max_depth;
  std::string validate() const;
};

// Fills T_21 (camera 2 from camera 1, as every pnpba result), ok/failure and the total time
// (the images' conversion to Open3D's included) of a TwoViewResult; no covariance. Needs
// depth2. Throws Error for inputs estimateTwoView would reject, when the plugin is missing, or
// with what Open3D threw.
// Open3D's own success flag decides ok: it says nothing about whether the pose is right.
TwoViewResult estimateTwoViewOpen3dOdometry(const cv::Mat& image1, const cv::Mat& depth1,
                                            const cv::Mat& image2, const cv::Mat& depth2,
                                            const Camera& camera,
                                            const Open3dOdometryOptions& options = {});

}  // namespace pnpba
