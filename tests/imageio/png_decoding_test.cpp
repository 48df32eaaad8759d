// The libpng decoder (imageio/src/png_decoding.h) against cv::imdecode, which the plugin path
// uses: every bit depth and colour type a PNG can have, with and without transparency and
// interlacing, under every flag it takes, the same type and the same pixels; and what it does
// not take (other flags, other formats, EXIF, damage) left to OpenCV.
#include "png_decoding.h"

#include <gtest/gtest.h>
#include <png.h>

#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>
#include <vector>

#include "decoded_as_opencv.h"

namespace pnpba {
namespace {

struct PngSpec {
  int bit_depth, colour_type;
  bool transparency = false, interlaced = false;
  std::string name() const {
    return "depth " + std::to_string(bit_depth) + " colour type " + std::to_string(colour_type) +
           (transparency ? " tRNS" : "") + (interlaced ? " Adam7" : "");
  }
};

void appendBytes(png_structp png, png_bytep data, png_size_t n) {
  auto* out = static_cast<std::vector<unsigned char>*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + n);
}
void noFlush(png_structp) {}

// A 37 x 23 PNG of random samples (odd sizes: partial bytes at low bit depths, ragged Adam7
// passes), written by libpng.
std::vector<unsigned char> randomPng(const PngSpec& s, unsigned seed) {
  constexpr int kWidth = 37, kHeight = 23;
  std::vector<unsigned char> out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png)) != 0) {
    png_destroy_write_struct(&png, &info);
    ADD_FAILURE() << "libpng could not write " << s.name();
    return {};
  }
  png_set_write_fn(png, &out, appendBytes, noFlush);
  png_set_IHDR(png, info, kWidth, kHeight, s.bit_depth, s.colour_type,
               s.interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  std::mt19937 rng(seed);
  std::vector<png_color> palette(1 << std::min(s.bit_depth, 8));
  std::vector<png_byte> alphas(palette.size());
  if (s.colour_type == PNG_COLOR_TYPE_PALETTE) {
    for (png_color& c : palette) c = {png_byte(rng()), png_byte(rng()), png_byte(rng())};
    png_set_PLTE(png, info, palette.data(), static_cast<int>(palette.size()));
  }
  png_color_16 key{};
  key.red = key.green = key.blue = key.gray = 3;
  if (s.transparency) {
    for (png_byte& a : alphas) a = png_byte(rng());
    png_set_tRNS(png, info, alphas.data(), static_cast<int>(alphas.size()), &key);
  }
  png_write_info(png, info);
  std::vector<std::vector<png_byte>> rows(kHeight,
                                          std::vector<png_byte>(png_get_rowbytes(png, info)));
  std::vector<png_bytep> pointers;
  for (auto& row : rows) {
    for (png_byte& b : row) b = png_byte(rng());
    pointers.push_back(row.data());
  }
  png_write_image(png, pointers.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
}

std::vector<PngSpec> everyKind() {
  std::vector<PngSpec> specs;
  for (bool interlaced : {false, true}) {
    for (int d : {1, 2, 4, 8, 16}) specs.push_back({d, PNG_COLOR_TYPE_GRAY, false, interlaced});
    for (int d : {8, 16}) {
      specs.push_back({d, PNG_COLOR_TYPE_GRAY, true, interlaced});
      specs.push_back({d, PNG_COLOR_TYPE_GRAY_ALPHA, false, interlaced});
      specs.push_back({d, PNG_COLOR_TYPE_RGB, false, interlaced});
      specs.push_back({d, PNG_COLOR_TYPE_RGB, true, interlaced});
      specs.push_back({d, PNG_COLOR_TYPE_RGB_ALPHA, false, interlaced});
    }
    for (int d : {1, 2, 4, 8}) {
      specs.push_back({d, PNG_COLOR_TYPE_PALETTE, false, interlaced});
      specs.push_back({d, PNG_COLOR_TYPE_PALETTE, true, interlaced});
    }
  }
  return specs;
}

TEST(PngDecoding, EveryKindOfPngDecodesAsOpenCvDecodesIt) {
  unsigned seed = 1;
  for (const PngSpec& spec : everyKind()) {
    const std::vector<unsigned char> bytes = randomPng(spec, seed++);
    ASSERT_FALSE(bytes.empty());
    test::expectDecodedAsOpenCv(decodePng, bytes, spec.name());
  }
}

TEST(PngDecoding, LeavesToOpenCvWhatItDoesNotTake) {
  const std::vector<unsigned char> png = randomPng({8, PNG_COLOR_TYPE_RGB}, 9);
  cv::Mat out(2, 2, CV_8UC1, cv::Scalar(7));
  // Flags it does not mirror: another colour choice, a reduced size.
  EXPECT_FALSE(decodePng(png.data(), png.size(), cv::IMREAD_ANYCOLOR, &out));
  EXPECT_FALSE(decodePng(png.data(), png.size(), cv::IMREAD_REDUCED_COLOR_2, &out));
  // Another format.
  std::vector<unsigned char> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", cv::Mat(8, 8, CV_8UC3, cv::Scalar(1, 2, 3)), jpeg));
  EXPECT_FALSE(decodePng(jpeg.data(), jpeg.size(), cv::IMREAD_COLOR, &out));
  // Damaged: cut short, or a byte of the image data changed (its checksum fails).
  std::vector<unsigned char> cut(png.begin(), png.begin() + static_cast<long>(png.size() / 2));
  EXPECT_FALSE(decodePng(cut.data(), cut.size(), cv::IMREAD_COLOR, &out));
  std::vector<unsigned char> flipped = png;
  flipped[flipped.size() - 20] ^= 0x55;
  EXPECT_FALSE(decodePng(flipped.data(), flipped.size(), cv::IMREAD_COLOR, &out));
  // EXIF, whose orientation OpenCV applies: an eXIf chunk inserted after IHDR (8 + 25 bytes).
  const unsigned char exif[] = {0, 0, 0, 0, 'e', 'X', 'I', 'f', 0, 0, 0, 0};
  std::vector<unsigned char> with_exif(png.begin(), png.begin() + 33);
  with_exif.insert(with_exif.end(), std::begin(exif), std::end(exif));
  with_exif.insert(with_exif.end(), png.begin() + 33, png.end());
  EXPECT_FALSE(decodePng(with_exif.data(), with_exif.size(), cv::IMREAD_COLOR, &out));
  EXPECT_FALSE(decodePng(nullptr, 0, cv::IMREAD_COLOR, &out));
  // *out untouched by every refusal.
  EXPECT_EQ(out.type(), CV_8UC1);
  EXPECT_EQ(out.at<unsigned char>(1, 1), 7);
}

}  // namespace
}  // namespace pnpba
