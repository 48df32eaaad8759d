// SIFT keypoint positions against rendered blobs with known centres, and the first-octave-0
// detector against OpenCV's own (first octave -1) on a real image.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "pnpba/core/error.h"
#include "pnpba/features/orb_features.h"

namespace pnpba {
namespace {

OrbOptions siftOptions(int first_octave, int features) {
  OrbOptions o;
  o.detector = Detector::kSift;
  o.num_features = features;
  o.sift_first_octave = first_octave;
  return o;
}

// A bright Gaussian blob of the given sigma centred at (cx, cy) in pixel-centre coordinates.
cv::Mat blobImage(cv::Size size, double cx, double cy, double sigma) {
  cv::Mat image(size, CV_8U);
  for (int v = 0; v < image.rows; ++v) {
    for (int u = 0; u < image.cols; ++u) {
      const double r2 = (u - cx) * (u - cx) + (v - cy) * (v - cy);
      image.at<uint8_t>(v, u) =
          cv::saturate_cast<uint8_t>(40 + 180 * std::exp(-r2 / (2 * sigma * sigma)));
    }
  }
  return image;
}

// Twelve blobs of this sigma at scattered centres, on images whose sizes are not all multiples of
// the shrink factor (the shrunk image drops the last columns and rows): each found within
// `max_px` of its centre, and the mean offset (x, y) within `max_bias_px` of zero.
void expectKeypointsOnBlobCentres(const OrbOptions& o, double sigma, double max_px,
                                  double max_bias_px, const std::string& what) {
  double sum_x = 0, sum_y = 0;
  int found = 0;
  for (int t = 0; t < 12; ++t) {
    const cv::Size size(321 - (t % 4), 241 - (t % 4));
    const double cx = 100 + t * 7.37, cy = 110 + t * 2.91;
    const Features f = detectOrb(blobImage(size, cx, cy, sigma), o);
    for (const cv::KeyPoint& k : f.keypoints) {
      if (std::hypot(k.pt.x - cx, k.pt.y - cy) > 1.5) continue;
      EXPECT_LT(std::hypot(k.pt.x - cx, k.pt.y - cy), max_px) << what;
      sum_x += k.pt.x - cx;
      sum_y += k.pt.y - cy;
      ++found;
      break;
    }
  }
  ASSERT_EQ(found, 12) << what << ", sigma " << sigma;
  EXPECT_NEAR(sum_x / found, 0.0, max_bias_px) << what;
  EXPECT_NEAR(sum_y / found, 0.0, max_bias_px) << what;
}

// OpenCV's own coordinates sit a quarter pixel off; a half pixel if halving were mapped back by
// pixel centres.
TEST(SiftFeatures, KeypointsSitOnBlobCentresAtEveryFirstOctave) {
  for (int first_octave : {-1, 0, 1}) {
    // Blobs the first octave can resolve: at octave 1 the image is seen at half resolution.
    for (double sigma : {first_octave == 1 ? 5.0 : 2.5, first_octave == 1 ? 6.0 : 4.0}) {
      expectKeypointsOnBlobCentres(siftOptions(first_octave, 10), sigma, 0.1, 0.02,
                                   "first octave " + std::to_string(first_octave));
    }
  }
}

// A fraction of an octave (the image resampled by area by a factor that is not a power of two):
// keypoints still sit on the blobs' centres.
TEST(SiftFeatures, KeypointsSitOnBlobCentresAtAFractionOfAnOctave) {
  for (double fraction : {0.77, 0.6}) {
    OrbOptions o = siftOptions(0, 10);
    o.sift_octave_fraction = fraction;
    expectKeypointsOnBlobCentres(o, 4.0, 0.15, 0.03, "fraction " + std::to_string(fraction));
  }
}

TEST(SiftFeatures, FirstOctaveZeroFindsOpenCvsCoarserKeypointsWhereTheyAre) {
  const cv::Mat image = cv::imread(std::string(PNPBA_SOURCE_DIR) + "/data/images/1.png");
  ASSERT_FALSE(image.empty());
  const Features upsampled = detectOrb(image, siftOptions(-1, 3000));
  const Features own = detectOrb(image, siftOptions(0, 3000));
  ASSERT_GT(own.keypoints.size(), 300u);
  ASSERT_LT(own.keypoints.size(), upsampled.keypoints.size());
  std::vector<cv::DMatch> matches;
  cv::BFMatcher(cv::NORM_L2, true).match(own.descriptors, upsampled.descriptors, matches);
  std::vector<float> dx, dy;
  int same_octave = 0;
  for (const cv::DMatch& m : matches) {
    const cv::KeyPoint& a = own.keypoints[m.queryIdx];
    const cv::KeyPoint& b = upsampled.keypoints[m.trainIdx];
    if (cv::norm(a.pt - b.pt) > 2 || std::abs(a.size / b.size - 1) > 0.2) continue;
    dx.push_back(a.pt.x - b.pt.x);
    dy.push_back(a.pt.y - b.pt.y);
    same_octave += static_cast<int8_t>(a.octave & 255) == static_cast<int8_t>(b.octave & 255);
  }
  ASSERT_GT(dx.size(), own.keypoints.size() / 3);
  auto median = [](std::vector<float> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  EXPECT_NEAR(median(dx), 0.0, 0.05);
  EXPECT_NEAR(median(dy), 0.0, 0.05);
  EXPECT_GT(same_octave, static_cast<int>(0.9 * dx.size()));
  for (const cv::KeyPoint& k : own.keypoints) {
    EXPECT_GE(static_cast<int8_t>(k.octave & 255), 0);  // nothing finer than the image
  }
}

TEST(SiftFeatures, OptionsAreValidated) {
  OrbOptions o = siftOptions(-2, 100);
  EXPECT_NE(o.validate(), "");
  o.sift_first_octave = 5;
  EXPECT_NE(o.validate(), "");
  o.sift_first_octave = 0;
  EXPECT_EQ(o.validate(), "");
  for (double bad : {0.5, 1.01, std::nan("")}) {
    o.sift_octave_fraction = bad;
    EXPECT_EQ(o.validate(), "SIFT octave fraction must be in (0.5, 1]") << bad;
  }
  o.sift_octave_fraction = 1;
  o.sift_contrast_threshold = 0;
  EXPECT_NE(o.validate(), "");
  EXPECT_THROW(detectOrb(cv::Mat(64, 64, CV_8U, cv::Scalar(0)), o), Error);
}

}  // namespace
}  // namespace pnpba
