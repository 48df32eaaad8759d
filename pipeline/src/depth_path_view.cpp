// The depth path's working images (two_view_stages.h: DepthPathView).
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

int workingHalvings(cv::Size image) {
  int halvings = 0;
  for (long pixels = static_cast<long>(image.width) * image.height; pixels > kWorkingMaxPixels;
       pixels /= 4) {
    ++halvings;
  }
  return halvings;
}

DepthPathView depthPathView(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                            const cv::Mat& depth2, const Camera& camera) {
  DepthPathView view{image1, depth1, image2, depth2, camera, 0};
  for (int k = workingHalvings(image1.size()); k > 0; --k) {
    view.image1 = halvedColour(view.image1);
    view.image2 = halvedColour(view.image2);
    view.depth1 = halvedDepth(view.depth1);
    if (!view.depth2.empty()) view.depth2 = halvedDepth(view.depth2);
    ++view.halvings;
  }
  view.camera.pinhole = halvedCamera(camera.pinhole, view.halvings);
  if (camera.width > 0) view.camera.width = view.image1.cols, view.camera.height = view.image1.rows;
  return view;
}

}  // namespace pnpba
