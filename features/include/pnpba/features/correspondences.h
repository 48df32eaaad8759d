// 3D-2D correspondences of a two-view RGB-D problem: each ORB match whose image-1 keypoint has
// a depth becomes a point in camera 1 and its pixel in image 2. With distortion, keypoints are
// undistorted before any geometry; depth is still read at the raw image-1 pixel.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "pnpba/features/depth_lookup.h"
#include "pnpba/features/orb_features.h"
#include "pnpba/features/pinhole_camera.h"

namespace pnpba {

struct Correspondence {
  Eigen::Vector3d X_1 = Eigen::Vector3d::Zero();   // point in camera 1 (m)
  Eigen::Vector2d uv_2 = Eigen::Vector2d::Zero();  // undistorted pixel in image 2
  Eigen::Vector2d uv_1 = Eigen::Vector2d::Zero();  // undistorted pixel in image 1
  double depth = 0;                                // depth 1 (m)
  int descriptor_distance = 0;
  int keypoint_1 = -1, keypoint_2 = -1;  // indices into the two keypoint lists
};
using Correspondences = std::vector<Correspondence>;

// Undistorted pixel positions of `keypoints` (the same positions when the camera has none).
std::vector<Eigen::Vector2d> undistortKeypoints(const std::vector<cv::KeyPoint>& keypoints,
                                                const PinholeCamera& camera);

Correspondences buildCorrespondences(const Features& features1, const Features& features2,
                                     const std::vector<cv::DMatch>& matches, const cv::Mat& depth1,
                                     const PinholeCamera& camera, const DepthOptions& depth_options,
                                     bool undistort = true);

}  // namespace pnpba
