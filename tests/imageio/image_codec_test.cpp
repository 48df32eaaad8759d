// Image codecs through the plugin: what is encoded decodes to the same pixels (colour and
// 16-bit depth), and what is not an image decodes to nothing, as cv::imdecode does.
#include "pnpba/imageio/image_codec.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "scratch_dir.h"

namespace pnpba {
namespace {

cv::Mat randomImage(int type, unsigned seed) {
  cv::Mat m(48, 64, type);
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, 0, type == CV_16UC1 ? 65535 : 255);
  return m;
}

TEST(ImageCodec, PngRoundTripKeepsEveryPixel) {
  for (int type : {CV_8UC1, CV_8UC3, CV_16UC1}) {
    const cv::Mat image = randomImage(type, 7 + type);
    std::vector<unsigned char> png;
    ASSERT_TRUE(encodeImage(".png", image, &png));
    const cv::Mat back = decodeImage(png, cv::IMREAD_UNCHANGED);
    ASSERT_EQ(back.type(), image.type());
    EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0) << "type " << type;
  }
}

TEST(ImageCodec, JpegQualityParameterIsPassedOn) {
  const cv::Mat image = randomImage(CV_8UC3, 3);
  std::vector<unsigned char> low, high;
  ASSERT_TRUE(encodeImage(".jpg", image, &low, {cv::IMWRITE_JPEG_QUALITY, 10}));
  ASSERT_TRUE(encodeImage(".jpg", image, &high, {cv::IMWRITE_JPEG_QUALITY, 95}));
  EXPECT_LT(low.size(), high.size());
}

TEST(ImageCodec, WhatIsNotAnImageDecodesToNothing) {
  EXPECT_TRUE(decodeImage({}, cv::IMREAD_COLOR).empty());
  EXPECT_TRUE(decodeImage({1, 2, 3, 4, 5}, cv::IMREAD_COLOR).empty());
  std::vector<unsigned char> png;
  ASSERT_TRUE(encodeImage(".png", randomImage(CV_8UC1, 1), &png));
  png.resize(png.size() / 2);  // truncated
  EXPECT_TRUE(decodeImage(png, cv::IMREAD_UNCHANGED).empty());
  EXPECT_FALSE(encodeImage(".no_such_format", randomImage(CV_8UC1, 1), &png));
}

TEST(ImageCodec, LoadImageReadsAFileAndGivesNothingForAMissingOne) {
  const std::string path = (pnpba::test::scratchDir() / "pnpba_image_codec_test.png").string();
  const cv::Mat image = randomImage(CV_8UC3, 5);
  std::vector<unsigned char> png;
  ASSERT_TRUE(encodeImage(".png", image, &png));
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  const cv::Mat back = loadImage(path, cv::IMREAD_COLOR);
  std::filesystem::remove(path);
  ASSERT_FALSE(back.empty());
  EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0);
  EXPECT_TRUE(loadImage(path, cv::IMREAD_COLOR).empty());
}

}  // namespace
}  // namespace pnpba
