// Depth of a keypoint from a 16-bit depth image (DESIGN.md section 3): metres = value /
// depth_scale, 0 = no depth (and 65535: withoutSaturatedDepth). The image is indexed at the RAW
// (distorted) keypoint, because depth is registered to raw pixels: at the nearest pixel by default,
// or truncated to the integer pixel as the textbook program does (which reads half a pixel off on
// average for the sub-pixel keypoints of coarser pyramid levels).
#pragma once

#include <cstdint>
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

// The top of the 16-bit range, which some datasets and drivers write where the sensor measured
// nothing (Microsoft's 7-Scenes, a saturated range): no depth, as 0 is. No real depth is read
// there: 65.5 m at 1000 units per metre, 13.1 m at TUM's 5000.
constexpr uint16_t kSaturatedDepth = 65535;

// `depth` itself (no copy) when it holds no kSaturatedDepth, else a copy with those pixels 0, so
// that every stage after it reads them as holes rather than as surfaces far away.
cv::Mat withoutSaturatedDepth(const cv::Mat& depth);

// Throws Error naming `what` unless `depth` is a non-empty 16-bit single-channel image with at
// least one value that is neither 0 nor kSaturatedDepth.
void checkDepthImage(const cv::Mat& depth, const std::string& what);

// Depth in metres at pixel (u, v), or nothing when outside the image, missing, out of
// [min_depth, max_depth], or on a depth edge (if rejected).
std::optional<double> depthAt(const cv::Mat& depth, double u, double v,
                              const DepthOptions& options);

}  // namespace pnpba
