// Reading the two-view inputs from files with errors that name the file: colour images as
// 8-bit BGR or grey (a 16-bit file is refused: it is a depth image given in the wrong place,
// which OpenCV would silently scale to 8 bits), depth images exactly as stored.
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace pnpba {

// Throws Error "<path>: <problem>".
cv::Mat readColourImage(const std::string& path);
cv::Mat readDepthImage(const std::string& path);

// A pair's four files read side by side on both cores (depth2 empty: none), each as the readers
// above read it; the error thrown is the first file's in this order that has one.
struct TwoViewImages {
  cv::Mat image1, image2, depth1, depth2;
};
TwoViewImages readTwoViewImages(const std::string& image1, const std::string& image2,
                                const std::string& depth1, const std::string& depth2);

}  // namespace pnpba
