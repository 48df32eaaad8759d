#include "pnpba/synthetic/sensor_effects.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>  // the flags; the codecs come through pnpba::imageio
#include <opencv2/imgproc.hpp>
#include <vector>

#include "pnpba/core/error.h"
#include "pnpba/imageio/image_codec.h"

namespace pnpba {

namespace {

void quantiseDisparity(double fb, int subpixel, double scale, cv::Mat* depth) {
  for (int v = 0; v < depth->rows; ++v) {
    for (int u = 0; u < depth->cols; ++u) {
      uint16_t& d = depth->at<uint16_t>(v, u);
      if (d == 0) continue;
      const double steps = std::round(fb * subpixel / (d / scale));
      if (steps < 1) {
        d = 0;  // beyond the last disparity step: the sensor reports nothing
        continue;
      }
      d = static_cast<uint16_t>(std::clamp(std::lround(fb * subpixel / steps * scale), 1L, 65535L));
    }
  }
}

void dropDepthEdges(int radius, cv::Mat* depth) {
  cv::Mat edge = cv::Mat::zeros(depth->size(), CV_8U);
  for (int v = 0; v < depth->rows; ++v) {
    for (int u = 0; u < depth->cols; ++u) {
      const double z = depth->at<uint16_t>(v, u);
      for (const auto& [du, dv] : {std::pair{1, 0}, std::pair{0, 1}}) {
        if (u + du >= depth->cols || v + dv >= depth->rows) continue;
        const double w = depth->at<uint16_t>(v + dv, u + du);
        if (z > 0 && w > 0 && std::abs(z - w) > 0.05 * std::min(z, w)) edge.at<uint8_t>(v, u) = 1;
      }
    }
  }
  cv::dilate(edge, edge,
             cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * radius + 1, 2 * radius + 1)));
  depth->setTo(0, edge);
}

}  // namespace

SensorEffects SensorEffects::kinectLike() {
  SensorEffects e;
  e.disparity_fb = 580.0 * 0.075;
  e.edge_hole_px = 2;
  e.depth_offset_px_x = 2;
  e.depth_offset_px_y = 1;
  e.jpeg_quality = 75;
  return e;
}

std::string SensorEffects::validate() const {
  if (!(disparity_fb >= 0) || !std::isfinite(disparity_fb)) return "disparity f*b must be >= 0";
  if (disparity_subpixel < 1) return "disparity subpixel steps must be >= 1";
  if (edge_hole_px < 0) return "edge holes must be >= 0 pixels";
  if (std::abs(depth_offset_px_x) > 20 || std::abs(depth_offset_px_y) > 20) {
    return "depth offset must be within 20 pixels";
  }
  if (jpeg_quality < 0 || jpeg_quality > 100) return "jpeg quality must be in 0..100";
  return "";
}

void applySensorEffects(const SensorEffects& e, double depth_scale, RenderedView* view) {
  const std::string problem = e.validate();
  if (!problem.empty()) throw Error(problem);
  if (e.disparity_fb > 0) {
    quantiseDisparity(e.disparity_fb, e.disparity_subpixel, depth_scale, &view->depth);
  }
  if (e.edge_hole_px > 0) dropDepthEdges(e.edge_hole_px, &view->depth);
  if (e.depth_offset_px_x != 0 || e.depth_offset_px_y != 0) {
    const cv::Mat shift =
        (cv::Mat_<double>(2, 3) << 1, 0, e.depth_offset_px_x, 0, 1, e.depth_offset_px_y);
    cv::Mat moved;
    cv::warpAffine(view->depth, moved, shift, view->depth.size(), cv::INTER_NEAREST,
                   cv::BORDER_CONSTANT, cv::Scalar(0));
    view->depth = moved;
  }
  if (e.jpeg_quality > 0) {
    std::vector<uchar> bytes;
    pnpba::encodeImage(".jpg", view->colour, &bytes, {cv::IMWRITE_JPEG_QUALITY, e.jpeg_quality});
    view->colour = pnpba::decodeImage(bytes, cv::IMREAD_COLOR);
  }
}

}  // namespace pnpba
