// The depth path's working images (two_view_stages.h: DepthPathView).
#include <oneapi/tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "area_resample.h"
#include "two_view_stages.h"

namespace pnpba {

namespace {

cv::Mat halvedDepth(const cv::Mat& depth) {
  cv::Mat out;
  everySecondPixel(depth, &out);
  return out;
}

cv::Mat halvedGrey(const cv::Mat& grey) {
  cv::Mat out;
  cv::pyrDown(grey, out, cv::Size(grey.cols / 2, grey.rows / 2));
  return out;
}

// One frame's working images: grey, halved `halvings` times, then resampled to `size` when that
// is smaller (depth from the nearest pixel centre: no depth blended across an edge).
void workingImages(const cv::Mat& image, const cv::Mat& depth, int halvings, cv::Size size,
                   cv::Mat* grey_out, cv::Mat* depth_out) {
  // The grey the alignment's pyramid would make of the full image, in floats, so that halving
  // and resampling round nothing.
  cv::Mat scratch, grey, d = depth;
  greyFloat(image, &scratch, &grey);
  for (int i = 0; i < halvings; ++i) {
    grey = halvedGrey(grey);
    if (!d.empty()) d = halvedDepth(d);
  }
  if (size != grey.size()) {
    grey = resampleByArea(grey, size);
    if (!d.empty()) {
      cv::Mat out;
      cv::resize(d, out, size, 0, 0, cv::INTER_NEAREST_EXACT);
      d = out;
    }
  }
  *grey_out = grey, *depth_out = d;
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
  cv::Size size = image1.size();
  for (double rest = scale; rest <= 0.5 + 1e-9; rest *= 2) {
    size = cv::Size(size.width / 2, size.height / 2);
    ++view.halvings;
  }
  const double rest = scale * (1 << view.halvings);
  if (rest < 1 - 1e-9) {
    const cv::Size halved = size;
    size = cv::Size(std::max(1, static_cast<int>(std::lround(halved.width * rest))),
                    std::max(1, static_cast<int>(std::lround(halved.height * rest))));
    view.scale_x = static_cast<double>(size.width) / halved.width;
    view.scale_y = static_cast<double>(size.height) / halved.height;
  }
  // The alignment reads the images only as grey: made grey first, each frame's on its own core
  // (a colour image's area resample cost 2-3 times a grey one's).
  tbb::parallel_invoke(
      [&] { workingImages(image1, depth1, view.halvings, size, &view.image1, &view.depth1); },
      [&] { workingImages(image2, depth2, view.halvings, size, &view.image2, &view.depth2); });
  view.camera.pinhole = viewPinhole(camera.pinhole, view);
  if (camera.width > 0) view.camera.width = view.image1.cols, view.camera.height = view.image1.rows;
  return view;
}

}  // namespace pnpba
