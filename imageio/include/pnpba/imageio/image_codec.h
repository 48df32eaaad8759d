// Image decoding and encoding: PNG and JPEG decoded by libpng and libjpeg as OpenCV decodes them,
// everything else by OpenCV's imgcodecs behind a plugin (pnpba/core/plugin.h), since that one
// library pulls in about 120 others and 90-150 ms that a tool's --help, a bad-input exit or a
// run on a dataset's PNGs and JPEGs should not pay. Same arguments and results as cv::imdecode /
// cv::imencode / cv::imread (flags: cv::ImreadModes, parameters: cv::ImwriteFlags pairs, both
// from <opencv2/imgcodecs.hpp>, whose enums need no linking). Throws Error only when the plugin
// is needed and cannot be loaded.
#pragma once

#include <istream>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace pnpba {

// The decoded image, or an empty Mat when the bytes are not an image OpenCV can decode.
cv::Mat decodeImage(const std::vector<unsigned char>& bytes, int flags);

// decodeImage without the plugin: true and the image for a PNG or JPEG that libpng or libjpeg
// decodes as OpenCV would (the same type and pixels), false for what decodeImage hands to
// OpenCV's codecs (other formats and flags, EXIF OpenCV would apply, CMYK, animation, damage).
// Prints nothing, loads nothing, and may run on several threads at once.
bool decodeImageWithoutPlugin(const std::vector<unsigned char>& bytes, int flags, cv::Mat* image);

// The encoded bytes; false when OpenCV cannot encode `image` as `extension` (".png", ".jpg").
bool encodeImage(const std::string& extension, const cv::Mat& image,
                 std::vector<unsigned char>* bytes, const std::vector<int>& params = {});

// The image in file `path`, or an empty Mat when it cannot be read or decoded (cv::imread).
cv::Mat loadImage(const std::string& path, int flags);

// Every byte left in `in`: in one read where the stream knows its size (a file), else to its end
// (a pipe). in.fail() tells whether the read failed.
std::vector<unsigned char> readAllBytes(std::istream& in);

}  // namespace pnpba
