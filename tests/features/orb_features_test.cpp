// ORB on a shrunk copy of a large image (OrbOptions::max_pixels): the keypoints come back in the
// image's own pixels, where ORB on the image itself finds the same corners.
#include "pnpba/features/orb_features.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <random>

#include "pnpba/core/error.h"

namespace pnpba {
namespace {

// Bright squares of 24-60 px on a dark ground at scattered places, their corners at every
// phase of any whole shrink factor, blurred as a lens would (FAST finds no corner on a perfect
// step at ORB's first level, and a copy shrunk by 3 x 3 means is nearly one again).
cv::Mat squaresImage(cv::Size size) {
  cv::Mat image(size, CV_8UC3, cv::Scalar(30, 30, 30));
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> side(24, 60);
  for (int y = 20; y + 80 < size.height; y += 97) {
    for (int x = 20; x + 80 < size.width; x += 101) {
      const int w = side(rng), h = side(rng);
      const int shade = 150 + (x + y) % 100;
      cv::rectangle(image, cv::Rect(x + (y / 97) % 5, y + (x / 101) % 5, w, h),
                    cv::Scalar(shade, shade, shade), cv::FILLED);
    }
  }
  cv::GaussianBlur(image, image, cv::Size(), 2.5);
  return image;
}

OrbOptions orbOptions(int max_pixels) {
  OrbOptions o;
  o.levels = 1;  // every keypoint at the copy's own resolution: the mapping alone is tested
  o.num_features = 3000;
  o.max_pixels = max_pixels;
  return o;
}

// Each keypoint found on a copy shrunk by `factor` lies within `factor` px of a keypoint found on
// the image itself, and their mean offset is within a quarter pixel of zero per axis: a copy's
// pixel centre mapped to the wrong place (a factor, or the half-pixel of a block's centre, left
// out) moves every keypoint the same way.
void expectSameCornersShrunkBy(int factor) {
  const cv::Mat image = squaresImage(cv::Size(1283, 965));  // not multiples of 2 or 3
  const Features own = detectOrb(image, orbOptions(0));
  const int cap = static_cast<int>(image.total() / (factor * factor)) + 1;
  const Features shrunk = detectOrb(image, orbOptions(cap));
  ASSERT_EQ(shrunk.pixel_scale, factor);
  ASSERT_GT(own.keypoints.size(), 300u);  // about four corners of each of 108 squares
  ASSERT_GT(shrunk.keypoints.size(), 250u);
  double sum_x = 0, sum_y = 0;
  int near = 0;
  for (const cv::KeyPoint& k : shrunk.keypoints) {
    double best = std::numeric_limits<double>::infinity();
    cv::Point2f offset;
    for (const cv::KeyPoint& o : own.keypoints) {
      const cv::Point2f d = k.pt - o.pt;
      if (d.dot(d) < best) best = d.dot(d), offset = d;
    }
    if (std::sqrt(best) > factor) continue;
    ++near, sum_x += offset.x, sum_y += offset.y;
  }
  EXPECT_GT(near, 0.7 * static_cast<double>(shrunk.keypoints.size()));
  EXPECT_NEAR(sum_x / near, 0.0, 0.25);
  EXPECT_NEAR(sum_y / near, 0.0, 0.25);
  EXPECT_FLOAT_EQ(shrunk.keypoints[0].size, factor * own.keypoints[0].size);
}

TEST(OrbFeatures, ShrunkByTwoFindsTheImagesOwnCorners) { expectSameCornersShrunkBy(2); }

TEST(OrbFeatures, ShrunkByThreeFindsTheImagesOwnCorners) { expectSameCornersShrunkBy(3); }

TEST(OrbFeatures, ImageWithinTheCapIsDetectedAsItIs) {
  const cv::Mat image = squaresImage(cv::Size(640, 480));
  const Features capped = detectOrb(image, orbOptions(640 * 480));
  const Features own = detectOrb(image, orbOptions(0));
  EXPECT_EQ(capped.pixel_scale, 1.0);
  ASSERT_EQ(capped.keypoints.size(), own.keypoints.size());
  for (size_t i = 0; i < own.keypoints.size(); ++i) {
    EXPECT_EQ(capped.keypoints[i].pt, own.keypoints[i].pt);
  }
}

TEST(OrbFeatures, NegativeCapIsRefused) {
  OrbOptions o;
  o.max_pixels = -1;
  EXPECT_FALSE(o.validate().empty());
  EXPECT_THROW(detectOrb(squaresImage(cv::Size(64, 48)), o), Error);
}

}  // namespace
}  // namespace pnpba
