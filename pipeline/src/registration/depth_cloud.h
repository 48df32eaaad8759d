// Private to the depth-only registration (registration.cpp): depth images back-projected into
// point clouds (optionally coloured from the registered colour image).
#pragma once

#include <memory>
#include <opencv2/core.hpp>

#include "cloud.h"
#include "pnpba/features/pinhole_camera.h"

namespace pnpba {

// Every stride-th pixel with depth in (0.1 m, max_range_m], undistorted when the camera has
// distortion. With a colour image (8-bit, 1 or 3 channels, the depth's size) each point gets
// the colour of its pixel as RGB in [0, 1]; a BGR image is read as OpenCV stores it.
std::shared_ptr<Cloud> depthCloud(const cv::Mat& depth, const PinholeCamera& camera,
                                  double depth_scale, int stride, double max_range_m,
                                  const cv::Mat& colour = cv::Mat());

}  // namespace pnpba
