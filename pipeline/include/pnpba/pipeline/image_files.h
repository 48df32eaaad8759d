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

}  // namespace pnpba
