// Open3D's RGB-D odometry, one of latency_bench's anchors: what a user who calls
// open3d::pipelines::odometry::ComputeRGBDOdometry (hybrid term, Open3D's default iterations)
// on the same pair gets, timed from the same cv::Mat images. It lives in a bench-only plugin
// (open3d_odometry_anchor.cpp, opened through pnpba/core/plugin.h) so that the bench links no
// Open3D of its own: the pipeline's registration plugin and its `--cold` load stay as a user's
// process has them.
#pragma once

#include <opencv2/core.hpp>

#include "pnpba/optimize/se3_quat.h"
#include "pnpba/pipeline/camera.h"

namespace pnpba::bench {

inline constexpr const char* kOdometryAnchorPlugin = "bench_open3d_odometry";
inline constexpr const char* kOdometryAnchorSymbol = "pnpba_bench_open3d_odometry";

struct OdometryAnchor {
  bool ok = false;  // Open3D's own success flag
  SE3Quat T_21;     // camera 2 from camera 1, from the identity (odometry's start)
  double ms = 0;    // the images' conversion included
};

// Colour 8-bit BGR or grey, depth 16-bit at camera.depth_scale per metre; depths outside
// [min_depth_m, max_depth_m] are ignored, as pnpba's depth lookup ignores them.
using Open3dOdometry = void(const cv::Mat* image1, const cv::Mat* depth1, const cv::Mat* image2,
                            const cv::Mat* depth2, const Camera* camera, double min_depth_m,
                            double max_depth_m, OdometryAnchor* out);

}  // namespace pnpba::bench
