// Private to the pipeline's .cpp files: depth images back-projected into Open3D point clouds
// (optionally coloured from the registered colour image), shared by the depth-only
// registration and the coloured alignment. Open3D stays behind this wall.
#pragma once

#include <open3d/geometry/PointCloud.h>

#include <memory>
#include <opencv2/core.hpp>

#include "pnpba/features/pinhole_camera.h"

namespace pnpba {

// Every stride-th pixel with depth in (0.1 m, max_range_m], undistorted when the camera has
// distortion. With a colour image (8-bit, 1 or 3 channels, the depth's size) each point gets
// the colour of its pixel as RGB in [0, 1]; a BGR image is read as OpenCV stores it.
std::shared_ptr<open3d::geometry::PointCloud> depthCloud(const cv::Mat& depth,
                                                         const PinholeCamera& camera,
                                                         double depth_scale, int stride,
                                                         double max_range_m,
                                                         const cv::Mat& colour = cv::Mat());

}  // namespace pnpba
