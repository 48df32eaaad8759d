// The pair's files read side by side (pnpba/pipeline/image_files.h): the same images as the
// single readers give, the error of the first bad file in argument order whatever finishes
// first, and files of other formats (OpenCV's codecs, one at a time) read beside PNGs.
#include "pnpba/pipeline/image_files.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "pnpba/core/error.h"
#include "scratch_dir.h"

namespace pnpba {
namespace {

namespace fs = std::filesystem;
const std::string kImages = std::string(PNPBA_SOURCE_DIR) + "/data/images/";

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.type() == b.type() && a.size() == b.size() && cv::norm(a, b, cv::NORM_INF) == 0;
}

TEST(TwoViewImages, AreWhatTheSingleReadersGive) {
  const TwoViewImages r = readTwoViewImages(kImages + "1.png", kImages + "2.png",
                                            kImages + "1_depth.png", kImages + "2_depth.png");
  EXPECT_TRUE(same(r.image1, readColourImage(kImages + "1.png")));
  EXPECT_TRUE(same(r.image2, readColourImage(kImages + "2.png")));
  EXPECT_TRUE(same(r.depth1, readDepthImage(kImages + "1_depth.png")));
  EXPECT_TRUE(same(r.depth2, readDepthImage(kImages + "2_depth.png")));
  EXPECT_EQ(r.depth1.type(), CV_16UC1);
  const TwoViewImages no_depth2 =
      readTwoViewImages(kImages + "1.png", kImages + "2.png", kImages + "1_depth.png", "");
  EXPECT_TRUE(no_depth2.depth2.empty());
}

TEST(TwoViewImages, TheFirstBadFileInArgumentOrderIsReported) {
  const std::string missing = kImages + "no_such_file.png";
  try {
    // Image 2 and depth 1 both missing: image 2 is reported.
    readTwoViewImages(kImages + "1.png", missing, missing + "2", kImages + "2_depth.png");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), missing + ": cannot open file");
  }
  try {
    readTwoViewImages(kImages + "1_depth.png", kImages + "2.png", kImages + "1_depth.png", "");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(kImages + "1_depth.png: expected an 8-bit colour image"),
              std::string::npos)
        << e.what();
  }
}

TEST(TwoViewImages, OtherFormatsAreReadBesidePngs) {
  const fs::path dir = pnpba::test::scratchPath("pnpba_two_view_images");
  fs::create_directories(dir);
  const cv::Mat colour1 = cv::imread(kImages + "1.png", cv::IMREAD_UNCHANGED);
  const cv::Mat colour2 = cv::imread(kImages + "2.png", cv::IMREAD_UNCHANGED);
  ASSERT_TRUE(cv::imwrite((dir / "1.bmp").string(), colour1));
  ASSERT_TRUE(cv::imwrite((dir / "2.bmp").string(), colour2));
  const TwoViewImages r = readTwoViewImages((dir / "1.bmp").string(), (dir / "2.bmp").string(),
                                            kImages + "1_depth.png", kImages + "2_depth.png");
  fs::remove_all(dir);
  EXPECT_TRUE(same(r.image1, readColourImage(kImages + "1.png")));
  EXPECT_TRUE(same(r.image2, readColourImage(kImages + "2.png")));
  EXPECT_TRUE(same(r.depth2, readDepthImage(kImages + "2_depth.png")));
}

}  // namespace
}  // namespace pnpba
