// The libjpeg decoder (imageio/src/jpeg_decoding.h) against cv::imdecode: colour and grey JPEGs,
// baseline and progressive, with restart markers, of odd sizes and subsamplings, under every
// flag it takes, the same type and the same pixels; and what it does not take left to OpenCV.
#include "jpeg_decoding.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "decoded_as_opencv.h"

namespace pnpba {
namespace {

// A smooth pattern with noise on it (JPEG's blocks and subsampling both matter), 61 x 37.
cv::Mat testImage(int channels, unsigned seed) {
  cv::Mat image(37, 61, CV_8UC3);
  cv::RNG rng(seed);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      image.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<uchar>(4 * x + rng.uniform(0, 40)),
                                            cv::saturate_cast<uchar>(6 * y + rng.uniform(0, 40)),
                                            cv::saturate_cast<uchar>(3 * (x + y)));
    }
  }
  if (channels == 1) cv::cvtColor(image, image, cv::COLOR_BGR2GRAY);
  return image;
}

TEST(JpegDecoding, EveryKindOfJpegDecodesAsOpenCvDecodesIt) {
  struct Kind {
    std::string name;
    int channels;
    std::vector<int> params;
  };
  const std::vector<Kind> kinds = {
      {"colour", 3, {}},
      {"colour, quality 40", 3, {cv::IMWRITE_JPEG_QUALITY, 40}},
      {"colour, progressive", 3, {cv::IMWRITE_JPEG_PROGRESSIVE, 1}},
      {"colour, restart markers", 3, {cv::IMWRITE_JPEG_RST_INTERVAL, 2}},
      {"colour, luma and chroma qualities (no subsampling)",
       3,
       {cv::IMWRITE_JPEG_LUMA_QUALITY, 90, cv::IMWRITE_JPEG_CHROMA_QUALITY, 50}},
      {"grey", 1, {}},
      {"grey, progressive", 1, {cv::IMWRITE_JPEG_PROGRESSIVE, 1}},
  };
  unsigned seed = 1;
  for (const Kind& kind : kinds) {
    std::vector<unsigned char> bytes;
    ASSERT_TRUE(cv::imencode(".jpg", testImage(kind.channels, seed++), bytes, kind.params));
    test::expectDecodedAsOpenCv(decodeJpeg, bytes, kind.name);
  }
}

TEST(JpegDecoding, LeavesToOpenCvWhatItDoesNotTake) {
  std::vector<unsigned char> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", testImage(3, 5), jpeg));
  cv::Mat out(2, 2, CV_8UC1, cv::Scalar(7));
  EXPECT_FALSE(decodeJpeg(jpeg.data(), jpeg.size(), cv::IMREAD_ANYCOLOR, &out));
  EXPECT_FALSE(decodeJpeg(jpeg.data(), jpeg.size(), cv::IMREAD_REDUCED_COLOR_2, &out));
  std::vector<unsigned char> png;
  ASSERT_TRUE(cv::imencode(".png", testImage(3, 5), png));
  EXPECT_FALSE(decodeJpeg(png.data(), png.size(), cv::IMREAD_COLOR, &out));
  // Cut short: libjpeg would fill the rest in with a warning; OpenCV decides what that gives.
  const std::vector<unsigned char> cut(jpeg.begin(),
                                       jpeg.begin() + static_cast<long>(jpeg.size() * 2 / 3));
  EXPECT_FALSE(decodeJpeg(cut.data(), cut.size(), cv::IMREAD_COLOR, &out));
  // EXIF (an APP1 segment after SOI): its orientation OpenCV applies under IMREAD_COLOR, not
  // under IMREAD_UNCHANGED, which this decoder then takes.
  const unsigned char app1[] = {0xFF, 0xE1, 0x00, 0x08, 'E', 'x', 'i', 'f', 0, 0};
  std::vector<unsigned char> with_exif = jpeg;
  with_exif.insert(with_exif.begin() + 2, std::begin(app1), std::end(app1));
  EXPECT_FALSE(decodeJpeg(with_exif.data(), with_exif.size(), cv::IMREAD_COLOR, &out));
  EXPECT_EQ(out.type(), CV_8UC1);  // untouched by every refusal
  EXPECT_EQ(out.at<unsigned char>(1, 1), 7);
  cv::Mat unchanged;
  ASSERT_TRUE(decodeJpeg(with_exif.data(), with_exif.size(), cv::IMREAD_UNCHANGED, &unchanged));
  EXPECT_EQ(cv::norm(unchanged, cv::imdecode(with_exif, cv::IMREAD_UNCHANGED), cv::NORM_INF), 0);
}

}  // namespace
}  // namespace pnpba
