// Resampling a grey float image to a smaller size by area, as cv::resize(INTER_AREA) does, for the
// depth path's working images (depth_path_view.cpp). OpenCV takes its generic path for a fraction
// of a halving (832 x 624 -> 640 x 480: 3.5 ms a grey image on one core); the filter is separable
// with at most a few taps per output pixel, so a row pass over whole rows and a column pass over
// the result cost a fraction of that.
#pragma once

#include <opencv2/core.hpp>

namespace pnpba {

// `image` (CV_32FC1) to `size`, each output pixel the mean of the input area it covers (input
// pixels partly inside weigh by their share). Both sides of `size` at most the image's.
cv::Mat resampleByArea(const cv::Mat& image, cv::Size size);

}  // namespace pnpba
