#include "pnpba/features/depth_lookup.h"

#include <cmath>

#include "pnpba/core/error.h"

namespace pnpba {

std::string DepthOptions::validate() const {
  if (!std::isfinite(depth_scale) || !(depth_scale > 0)) return "depth scale must be > 0";
  if (!(min_depth >= 0) || !(max_depth > min_depth)) return "need 0 <= min depth < max depth";
  if (!(edge_relative_step > 0)) return "edge relative step must be > 0";
  return "";
}

void checkDepthImage(const cv::Mat& depth, const std::string& what) {
  if (depth.empty()) throw Error(what + ": depth image is empty or unreadable");
  if (depth.type() != CV_16UC1) {
    throw Error(what + ": depth must be a 16-bit single-channel image (got " +
                std::to_string(depth.elemSize1() * 8) + "-bit, " +
                std::to_string(depth.channels()) + " channel" + (depth.channels() == 1 ? "" : "s") +
                ")");
  }
  if (cv::countNonZero(depth) == 0) throw Error(what + ": depth image has no valid depth (all 0)");
}

std::optional<double> depthAt(const cv::Mat& depth, double u, double v,
                              const DepthOptions& options) {
  if (options.round_to_nearest) {
    u += 0.5;
    v += 0.5;
  }
  if (!(u >= 0) || !(v >= 0)) return std::nullopt;
  const int x = static_cast<int>(u), y = static_cast<int>(v);
  if (x >= depth.cols || y >= depth.rows) return std::nullopt;
  const uint16_t raw = depth.at<uint16_t>(y, x);
  if (raw == 0) return std::nullopt;
  const double z = raw / options.depth_scale;
  if (z < options.min_depth || z > options.max_depth) return std::nullopt;
  if (options.reject_depth_edges) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int xx = x + dx, yy = y + dy;
        if (xx < 0 || yy < 0 || xx >= depth.cols || yy >= depth.rows) return std::nullopt;
        const uint16_t n = depth.at<uint16_t>(yy, xx);
        if (n == 0 || std::abs(n - raw) > options.edge_relative_step * raw) return std::nullopt;
      }
    }
  }
  return z;
}

}  // namespace pnpba
