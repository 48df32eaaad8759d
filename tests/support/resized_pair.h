// An RGB-D pair as a sensor of another resolution would see it, for the benches and tests that
// check that the two-view pose does not depend on the images' size: colour by area (linear when
// enlarging), depth by nearest neighbour (no depth blended across edges), the intrinsics scaled
// with pixel centres kept at (x + 0.5) * factor - 0.5.
#pragma once

#include <opencv2/imgproc.hpp>

#include "pnpba/pipeline/camera.h"

namespace pnpba::bench {

inline void resizePair(double factor, cv::Mat* image1, cv::Mat* depth1, cv::Mat* image2,
                       cv::Mat* depth2, Camera* camera) {
  const int colour = factor < 1 ? cv::INTER_AREA : cv::INTER_LINEAR;
  for (cv::Mat* image : {image1, image2}) {
    cv::Mat out;
    cv::resize(*image, out, {}, factor, factor, colour);
    *image = out;
  }
  for (cv::Mat* depth : {depth1, depth2}) {
    if (depth->empty()) continue;
    cv::Mat out;
    cv::resize(*depth, out, {}, factor, factor, cv::INTER_NEAREST);
    *depth = out;
  }
  camera->pinhole.fx *= factor;
  camera->pinhole.fy *= factor;
  camera->pinhole.cx = (camera->pinhole.cx + 0.5) * factor - 0.5;
  camera->pinhole.cy = (camera->pinhole.cy + 0.5) * factor - 0.5;
  if (camera->width > 0) camera->width = image1->cols, camera->height = image1->rows;
}

}  // namespace pnpba::bench
