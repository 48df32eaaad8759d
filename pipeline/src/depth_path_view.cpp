// The depth path's working images (two_view_stages.h: DepthPathView).
#include <opencv2/imgproc.hpp>

#include "two_view_stages.h"

namespace pnpba {

namespace {

cv::Mat everySecondPixel(const cv::Mat& depth) {
  cv::Mat out(depth.rows / 2, depth.cols / 2, depth.type());
  for (int v = 0; v < out.rows; ++v) {
    const auto* in = depth.ptr<uint16_t>(2 * v);
    auto* row = out.ptr<uint16_t>(v);
    for (int u = 0; u < out.cols; ++u) row[u] = in[2 * u];
  }
  return out;
}

cv::Mat halvedColour(const cv::Mat& image) {
  cv::Mat out;
  cv::pyrDown(image, out, cv::Size(image.cols / 2, image.rows / 2));
  return out;
}

}  // namespace

int workingHalvings(cv::Size image) {
  int halvings = 0;
  for (long pixels = static_cast<long>(image.width) * image.height; pixels > kWorkingMaxPixels;
       pixels /= 4) {
    ++halvings;
  }
  return halvings;
}

PinholeCamera halvedCamera(PinholeCamera camera, int halvings) {
  // Distortion coefficients act on normalised coordinates: a scaled image keeps them.
  for (int i = 0; i < halvings; ++i) {
    camera.fx /= 2, camera.fy /= 2, camera.cx /= 2, camera.cy /= 2;
  }
  return camera;
}

DepthPathView depthPathView(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                            const cv::Mat& depth2, const Camera& camera) {
  DepthPathView view{image1, depth1, image2, depth2, camera, 0};
  for (int k = workingHalvings(image1.size()); k > 0; --k) {
    view.image1 = halvedColour(view.image1);
    view.image2 = halvedColour(view.image2);
    view.depth1 = everySecondPixel(view.depth1);
    if (!view.depth2.empty()) view.depth2 = everySecondPixel(view.depth2);
    ++view.halvings;
  }
  view.camera.pinhole = halvedCamera(camera.pinhole, view.halvings);
  if (camera.width > 0) view.camera.width = view.image1.cols, view.camera.height = view.image1.rows;
  return view;
}

}  // namespace pnpba
