// JPEG decoding with libjpeg itself, for the same reason as png_decoding.h: the colour images
// of some RGB-D datasets (TUM's fr3_cabinet key frames here, ScanNet's, Redwood's) are JPEG,
// and reading them through OpenCV's imgcodecs loads about 120 libraries. Asks libjpeg for what
// OpenCV's JPEG decoder asks for (RGB or grey out, then RGB to BGR), so the pixels and the type
// are cv::imdecode's, bit for bit (tests/imageio/jpeg_decoding_test.cpp).
#pragma once

#include <cstddef>
#include <opencv2/core.hpp>

namespace pnpba {

// True and the image in *out when `bytes` is a JPEG with one or three components that libjpeg
// decodes without error or warning, under IMREAD_UNCHANGED, IMREAD_GRAYSCALE or IMREAD_COLOR
// (IMREAD_ANYDEPTH changes nothing for 8 bits). False, *out untouched, for anything else: other
// formats and flags, CMYK, EXIF under flags whose orientation OpenCV applies, damage.
bool decodeJpeg(const unsigned char* bytes, size_t size, int flags, cv::Mat* out);

}  // namespace pnpba
