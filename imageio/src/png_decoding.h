// PNG decoding with libpng itself, so that reading the PNG files RGB-D datasets store their
// colour and depth in does not load OpenCV's imgcodecs: with its codecs (GDAL, GDCM, OpenEXR,
// HEIF, ...) about 120 shared libraries and 150 ms of a tool's run. Asks libpng for the
// transforms OpenCV 4's PNG decoder asks for, so the pixels and the type are cv::imdecode's,
// bit for bit (tests/imageio/png_decoding_test.cpp compares them over bit depths, colour types,
// transparency, interlacing and flags).
#pragma once

#include <cstddef>
#include <opencv2/core.hpp>

namespace pnpba {

// True and the image in *out when `bytes` is a single-image PNG this decoder takes with these
// cv::ImreadModes flags (IMREAD_UNCHANGED, IMREAD_GRAYSCALE, IMREAD_COLOR, with or without
// IMREAD_ANYDEPTH) and libpng decodes without error. False, *out untouched, for anything else:
// another format, other flags, an animated PNG, one with EXIF (its orientation OpenCV applies),
// or a damaged one; the caller then asks OpenCV, which decides as it always has.
bool decodePng(const unsigned char* bytes, size_t size, int flags, cv::Mat* out);

}  // namespace pnpba
