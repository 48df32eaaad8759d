// Private to the depth-only registration (registration.cpp): depth images back-projected into
// point clouds.
#pragma once

#include <memory>
#include <opencv2/core.hpp>

#include "cloud.h"
#include "pnpba/features/pinhole_camera.h"

namespace pnpba {

// Every stride-th pixel with depth in (0.1 m, max_range_m], undistorted when the camera has
// distortion.
std::shared_ptr<Cloud> depthCloud(const cv::Mat& depth, const PinholeCamera& camera,
                                  double depth_scale, int stride, double max_range_m);

}  // namespace pnpba
