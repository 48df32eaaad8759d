// The functions the imgcodecs plugin (imageio/plugin/imgcodecs_plugin.cpp) exports and
// image_codec.cpp calls. Both sides are built together and share OpenCV's core library, so the
// arguments are C++ types passed by pointer; neither function throws.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace pnpba {

inline constexpr const char* kImgcodecsPlugin = "imgcodecs";

// cv::imdecode; *image is empty when the bytes cannot be decoded.
using ImgcodecsDecode = void(const unsigned char* data, size_t size, int flags, cv::Mat* image);
// cv::imencode; false when it fails.
using ImgcodecsEncode = bool(const char* extension, const cv::Mat* image,
                             const std::vector<int>* params, std::vector<unsigned char>* bytes);

}  // namespace pnpba
