// Depth lookup: scale, holes, range, nearest-pixel vs truncation, depth edges and the border.
#include "pnpba/features/depth_lookup.h"

#include <gtest/gtest.h>

#include "pnpba/core/error.h"

namespace pnpba {
namespace {

// 10x8 image: left half 1.0 m, right half (x >= 5) 2.0 m at scale 5000; a hole at (2, 2).
cv::Mat stepImage(double scale = 5000.0) {
  cv::Mat d(8, 10, CV_16UC1);
  for (int y = 0; y < d.rows; ++y)
    for (int x = 0; x < d.cols; ++x)
      d.at<uint16_t>(y, x) = static_cast<uint16_t>((x < 5 ? 1.0 : 2.0) * scale);
  d.at<uint16_t>(2, 2) = 0;
  return d;
}

TEST(DepthLookup, MetresAreValueOverScale) {
  DepthOptions o;
  EXPECT_DOUBLE_EQ(*depthAt(stepImage(), 1, 1, o), 1.0);
  o.depth_scale = 1000.0;
  EXPECT_DOUBLE_EQ(*depthAt(stepImage(1000.0), 7, 1, o), 2.0);
  EXPECT_DOUBLE_EQ(*depthAt(stepImage(5000.0), 7, 1, o), 10.0);  // wrong scale: 5x farther
}

TEST(DepthLookup, HolesAndOutsideAreMissing) {
  const DepthOptions o;
  EXPECT_FALSE(depthAt(stepImage(), 2, 2, o));
  EXPECT_FALSE(depthAt(stepImage(), -0.6, 1, o));
  EXPECT_FALSE(depthAt(stepImage(), 9.6, 1, o));
  EXPECT_FALSE(depthAt(stepImage(), 1, 7.6, o));
  EXPECT_FALSE(depthAt(stepImage(), std::nan(""), 1, o));
}

TEST(DepthLookup, RangeLimits) {
  DepthOptions o;
  o.max_depth = 1.5;
  EXPECT_TRUE(depthAt(stepImage(), 1, 1, o));
  EXPECT_FALSE(depthAt(stepImage(), 7, 1, o));
  o.max_depth = 10;
  o.min_depth = 1.5;
  EXPECT_FALSE(depthAt(stepImage(), 1, 1, o));
}

TEST(DepthLookup, NearestPixelRoundsWhereTruncationDoesNot) {
  DepthOptions o;
  // u = 4.6 is nearest to column 5 (2 m); truncation reads column 4 (1 m).
  EXPECT_DOUBLE_EQ(*depthAt(stepImage(), 4.6, 1, o), 2.0);
  o.round_to_nearest = false;
  EXPECT_DOUBLE_EQ(*depthAt(stepImage(), 4.6, 1, o), 1.0);
}

TEST(DepthLookup, EdgeRejectionDropsStepsHolesAndTheBorder) {
  DepthOptions o;
  o.reject_depth_edges = true;
  EXPECT_TRUE(depthAt(stepImage(), 7, 5, o));   // flat 3x3
  EXPECT_FALSE(depthAt(stepImage(), 4, 5, o));  // neighbour at 2 m
  EXPECT_FALSE(depthAt(stepImage(), 3, 3, o));  // neighbour is the hole
  EXPECT_FALSE(depthAt(stepImage(), 0, 5, o));  // 3x3 leaves the image
  o.reject_depth_edges = false;
  EXPECT_TRUE(depthAt(stepImage(), 4, 5, o));
}

// 7-Scenes and some drivers write 65535 where they measured nothing; with max_depth lifted it
// would read as a surface 13.1 m away at scale 5000, so it is read as a hole.
TEST(DepthLookup, TheTopOfTheRangeIsAHole) {
  DepthOptions o;
  o.max_depth = 1e9;
  cv::Mat d = stepImage();
  d.at<uint16_t>(2, 2) = kSaturatedDepth;
  EXPECT_FALSE(depthAt(d, 2, 2, o));
  o.reject_depth_edges = true;
  EXPECT_FALSE(depthAt(d, 2, 3, o));  // its neighbour: next to a hole, as with a 0 there
  EXPECT_TRUE(depthAt(d, 1, 6, o));
}

TEST(DepthLookup, WithoutSaturatedDepthCopiesOnlyWhenItMust) {
  const cv::Mat plain = stepImage();
  const cv::Mat same = withoutSaturatedDepth(plain);
  EXPECT_EQ(same.data, plain.data);  // nothing to clear: no copy
  cv::Mat marked = stepImage();
  marked.at<uint16_t>(2, 2) = kSaturatedDepth;
  marked.at<uint16_t>(7, 9) = kSaturatedDepth;
  const cv::Mat cleared = withoutSaturatedDepth(marked);
  EXPECT_NE(cleared.data, marked.data);
  EXPECT_EQ(marked.at<uint16_t>(7, 9), kSaturatedDepth);  // the caller's image untouched
  cv::Mat expected = stepImage();
  expected.at<uint16_t>(7, 9) = 0;
  EXPECT_EQ(cv::countNonZero(cleared != expected), 0);
  EXPECT_TRUE(withoutSaturatedDepth(cv::Mat()).empty());
}

TEST(DepthLookup, CheckDepthImageNamesTheProblem) {
  try {
    checkDepthImage(cv::Mat(4, 4, CV_8UC1, cv::Scalar(3)), "d.png");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("d.png: depth must be a 16-bit"), std::string::npos);
  }
  EXPECT_THROW(checkDepthImage(cv::Mat(4, 4, CV_16UC1, cv::Scalar(0)), "z"), Error);
  try {
    checkDepthImage(cv::Mat(4, 4, CV_16UC1, cv::Scalar(kSaturatedDepth)), "s.png");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("s.png: depth image has no valid depth"),
              std::string::npos);
  }
  cv::Mat holes(6, 37, CV_16UC1, cv::Scalar(0));  // holes of both kinds, then one depth
  holes.colRange(0, 20).setTo(kSaturatedDepth);
  EXPECT_THROW(checkDepthImage(holes, "h"), Error);
  for (const uint16_t valid : {1, 65534}) {
    holes.at<uint16_t>(5, 36) = valid;
    EXPECT_NO_THROW(checkDepthImage(holes, "h")) << valid;
  }
  EXPECT_THROW(checkDepthImage(cv::Mat(), "z"), Error);
  EXPECT_NO_THROW(checkDepthImage(stepImage(), "z"));
  DepthOptions bad;
  bad.depth_scale = 0;
  EXPECT_NE(bad.validate(), "");
}

}  // namespace
}  // namespace pnpba
