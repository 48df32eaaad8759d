#include "pnpba/pipeline/image_files.h"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pnpba/core/error.h"

namespace pnpba {

namespace {

cv::Mat readImage(const std::string& path, int flags) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw Error(path + ": cannot open file");
  if (std::filesystem::is_directory(path, ec)) throw Error(path + ": is a folder, not an image");
  cv::Mat image;
  try {
    image = cv::imread(path, flags);
  } catch (const cv::Exception&) {
  }
  if (image.empty()) throw Error(path + ": not an image OpenCV can decode");
  return image;
}

}  // namespace

cv::Mat readColourImage(const std::string& path) {
  cv::Mat image = readImage(path, cv::IMREAD_UNCHANGED);
  if (image.depth() != CV_8U) {
    throw Error(path + ": expected an 8-bit colour image, got " +
                std::to_string(image.elemSize1() * 8) + "-bit (a depth image?)");
  }
  if (image.channels() == 4) {  // drop the alpha channel
    cv::Mat bgr;
    cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
    return bgr;
  }
  return image;
}

cv::Mat readDepthImage(const std::string& path) { return readImage(path, cv::IMREAD_UNCHANGED); }

}  // namespace pnpba
