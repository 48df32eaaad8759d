// The depth path's area resample (pipeline/src/area_resample.h) against OpenCV's
// cv::resize(INTER_AREA), which it stands in for, at the fractions of a halving sensors need.
#include "area_resample.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "pnpba/core/error.h"

namespace pnpba {
namespace {

cv::Mat randomGrey(cv::Size size, int seed) {
  cv::Mat image(size, CV_32FC1);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0.0, 255.0);
  return image;
}

TEST(AreaResample, MatchesOpenCvsAreaResampleAtFractionsOfAHalving) {
  const struct {
    cv::Size in, out;
  } cases[] = {
      {{832, 624}, {640, 480}},   // 1.3 x 640 x 480
      {{1280, 720}, {739, 416}},  // 1280 x 720 to 640 x 480's pixel count
      {{848, 480}, {737, 417}},   // 848 x 480, likewise
      {{101, 77}, {63, 50}},      // odd sizes, ratios that are no simple fraction
      {{640, 480}, {640, 240}},   // one side kept
      {{90, 60}, {30, 20}},       // whole ratios: OpenCV's box path
  };
  int seed = 1;
  for (const auto& c : cases) {
    const cv::Mat image = randomGrey(c.in, seed++);
    cv::Mat expected;
    cv::resize(image, expected, c.out, 0, 0, cv::INTER_AREA);
    const cv::Mat got = resampleByArea(image, c.out);
    ASSERT_EQ(got.size(), c.out);
    ASSERT_EQ(got.type(), CV_32FC1);
    // Values up to 255 summed in another order: float round-off only.
    EXPECT_LT(cv::norm(got, expected, cv::NORM_INF), 2e-3) << c.in << " -> " << c.out;
  }
}

TEST(AreaResample, KeepsAUniformImageAndTheMean) {
  const cv::Mat uniform(624, 832, CV_32FC1, cv::Scalar(37.5));
  const cv::Mat out = resampleByArea(uniform, {640, 480});
  double lo = 0, hi = 0;
  cv::minMaxLoc(out, &lo, &hi);
  EXPECT_NEAR(lo, 37.5, 1e-4);
  EXPECT_NEAR(hi, 37.5, 1e-4);
  // Every input pixel's area lands somewhere once: the means agree.
  const cv::Mat image = randomGrey({832, 624}, 7);
  EXPECT_NEAR(cv::mean(resampleByArea(image, {640, 480}))[0], cv::mean(image)[0], 1e-3);
}

TEST(AreaResample, RefusesAnotherTypeOrALargerSize) {
  EXPECT_THROW(resampleByArea(cv::Mat(10, 10, CV_8UC1), {5, 5}), Error);
  EXPECT_THROW(resampleByArea(cv::Mat(10, 10, CV_32FC1), {11, 5}), Error);
  EXPECT_THROW(resampleByArea(cv::Mat(10, 10, CV_32FC1), {0, 5}), Error);
}

}  // namespace
}  // namespace pnpba
