// The depth path's working images (two_view_stages.h: DepthPathView).
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "two_view_stages.h"

namespace pnpba {

namespace {

cv::Mat halvedDepth(const cv::Mat& depth) {
  cv::Mat out;
  everySecondPixel(depth, &out);
  return out;
}

cv::Mat halvedColour(const cv::Mat& image) {
  cv::Mat out;
  cv::pyrDown(image, out, cv::Size(image.cols / 2, image.rows / 2));
  return out;
}

}  // namespace

double workingScale(cv::Size image) {
  const double pixels = static_cast<double>(image.width) * image.height;
  // Up to 15 % over 640 x 480 (a 739 x 458 sensor: 10 %) is left as it is: resampling would cost
  // precision for little time.
  if (pixels <= 1.15 * kWorkingPixels) return 1.0;
  return std::sqrt(kWorkingPixels / pixels);
}

PinholeCamera viewPinhole(const PinholeCamera& camera, const DepthPathView& view) {
  PinholeCamera c = halvedCamera(camera, view.halvings);
  if (view.scale_x != 1 || view.scale_y != 1) {
    c.fx *= view.scale_x, c.fy *= view.scale_y;
    c.cx = (c.cx + 0.5) * view.scale_x - 0.5;
    c.cy = (c.cy + 0.5) * view.scale_y - 0.5;
  }
  return c;
}

DepthPathView depthPathView(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                            const cv::Mat& depth2, const Camera& camera) {
  DepthPathView view{image1, depth1, image2, depth2, camera, 0};
  const double scale = workingScale(image1.size());
  if (scale == 1.0) return view;
  // Halvings while they stay at or above the working size (exact for 1280 x 960), then the rest.
  for (double rest = scale; rest <= 0.5 + 1e-9; rest *= 2) {
    view.image1 = halvedColour(view.image1);
    view.image2 = halvedColour(view.image2);
    view.depth1 = halvedDepth(view.depth1);
    if (!view.depth2.empty()) view.depth2 = halvedDepth(view.depth2);
    ++view.halvings;
  }
  const double rest = scale * (1 << view.halvings);
  if (rest < 1 - 1e-9) {
    const cv::Size size(std::max(1, static_cast<int>(std::lround(view.image1.cols * rest))),
                        std::max(1, static_cast<int>(std::lround(view.image1.rows * rest))));
    view.scale_x = static_cast<double>(size.width) / view.image1.cols;
    view.scale_y = static_cast<double>(size.height) / view.image1.rows;
    for (cv::Mat* image : {&view.image1, &view.image2}) {
      cv::Mat out;
      cv::resize(*image, out, size, 0, 0, cv::INTER_AREA);
      *image = out;
    }
    for (cv::Mat* depth : {&view.depth1, &view.depth2}) {
      if (depth->empty()) continue;
      cv::Mat out;  // the nearest pixel centre: no depth blended across an edge
      cv::resize(*depth, out, size, 0, 0, cv::INTER_NEAREST_EXACT);
      *depth = out;
    }
  }
  view.camera.pinhole = viewPinhole(camera.pinhole, view);
  if (camera.width > 0) view.camera.width = view.image1.cols, view.camera.height = view.image1.rows;
  return view;
}

}  // namespace pnpba
