// Depth of a keypoint from a 16-bit depth image (DESIGN.md section 3): metres = value /
// depth_scale, 0 = no depth. The image is indexed at the RAW (distorted) keypoint, because
// depth is registered to raw pixels: at the nearest pixel by default, or truncated to the
// integer pixel as the textbook program does (which reads half a pixel off on average for the
// sub-pixel keypoints of coarser pyramid levels).
#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <string>

namespace pnpba {

struct DepthOptions {
  double depth_scale = 5000.0;  // TUM and the textbook pair; 1000 for many other sensors
  double min_depth = 0.1;       // m
  double max_depth = 10.0;      // m
  // Reject a keypoint whose 3x3 neighbourhood disagrees (a depth edge): any neighbour missing
  // or differing by more than edge_relative_step * depth.
  bool reject_depth_edges = false;
  bool round_to_nearest = true;  // false: the textbook's truncation
  double edge_relative_step = 0.05;
  std::string validate() const;
};

// Throws Error naming `what` unless `depth` is a non-empty 16-bit single-channel image with at
// least one non-zero value.
void checkDepthImage(const cv::Mat& depth, const std::string& what);

// Depth in metres at pixel (u, v), or nothing when outside the image, missing, out of
// [min_depth, max_depth], or on a depth edge (if rejected).
std::optional<double> depthAt(const cv::Mat& depth, double u, double v,
                              const DepthOptions& options);

}  // namespace pnpba
