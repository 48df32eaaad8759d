// SIFT detection on the descriptors' scale space against OpenCV's detect, every keypoint field to
// the bit: on the shared real images (colour, grey, and shrunk as the SIFT retry shrinks them),
// on made-up textures turned every way, at other contrast thresholds and feature counts, and on
// a small image; the descriptors from the shared scale space equal detectAndCompute's.
#include "sift_detection.h"

#include <gtest/gtest.h>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

#include "pnpba/core/error.h"
#include "sift_test_images.h"

namespace pnpba {
namespace {

// Blurred random blobs turned by `degrees`: extrema at every scale, orientation and border.
cv::Mat blobs(double degrees, unsigned seed, cv::Size size = cv::Size(400, 300)) {
  cv::theRNG().state = seed;
  cv::Mat noise(size, CV_8U), blurred;
  cv::randu(noise, 0, 256);
  cv::GaussianBlur(noise, blurred, cv::Size(), 2.5);
  cv::normalize(blurred, blurred, 0, 255, cv::NORM_MINMAX);
  const cv::Mat turn = cv::getRotationMatrix2D(cv::Point2f(size.width / 2.f, size.height / 2.f),
                                               degrees, 1.0 + 0.01 * (seed % 7));
  cv::Mat turned;
  cv::warpAffine(blurred, turned, turn, size, cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return turned;
}

// The number of keypoints whose fields differ from OpenCV's (and the counts' difference).
int differingKeypoints(const cv::Mat& image, int features, double contrast, size_t* count) {
  std::vector<cv::KeyPoint> reference;
  cv::SIFT::create(features, 3, contrast)->detect(image, reference);
  const std::vector<cv::KeyPoint> ours =
      siftKeypoints(siftDetectionScaleSpace(image), features, contrast);
  *count = reference.size();
  int differ = static_cast<int>(std::max(ours.size(), reference.size()) -
                                std::min(ours.size(), reference.size()));
  for (size_t i = 0; i < std::min(ours.size(), reference.size()); ++i) {
    const cv::KeyPoint& a = ours[i];
    const cv::KeyPoint& b = reference[i];
    differ += a.pt != b.pt || a.size != b.size || a.angle != b.angle || a.response != b.response ||
              a.octave != b.octave || a.class_id != b.class_id;
  }
  return differ;
}

void expectOpenCvsKeypoints(const cv::Mat& image, int features, double contrast,
                            const std::string& what) {
  size_t count = 0;
  EXPECT_EQ(differingKeypoints(image, features, contrast, &count), 0)
      << what << " (" << count << " keypoints)";
  EXPECT_GT(count, 20u) << what;
}

TEST(SiftDetection, EqualsOpenCvsOnTheSharedImages) {
  if (!siftDetectionAvailable()) GTEST_SKIP() << "no AVX2 and FMA here, or AVX-512";
  const std::vector<testing::SiftTestImage> images =
      testing::sharedSiftTestImages({"tum_fr1_desk/rgb", "tum_fr3_cabinet_keyframes/rgb"});
  if (images.empty()) GTEST_SKIP() << "no shared data";
  EXPECT_GE(images.size(), 6u);
  for (const testing::SiftTestImage& t : images) {
    expectOpenCvsKeypoints(t.image, t.features, t.contrast, t.what);
  }
}

TEST(SiftDetection, EqualsOpenCvsOnTurnedTexturesAndSmallImages) {
  if (!siftDetectionAvailable()) GTEST_SKIP() << "no AVX2 and FMA here, or AVX-512";
  for (int t = 0; t < 8; ++t) {
    const double degrees = 45.0 * t + 7.0;
    expectOpenCvsKeypoints(blobs(degrees, 21 + t), 3000, 0.02 + 0.005 * t,
                           "texture turned " + std::to_string(degrees) + " deg");
  }
  expectOpenCvsKeypoints(blobs(30, 5, cv::Size(96, 72)), 500, 0.02, "96 x 72");
  expectOpenCvsKeypoints(blobs(10, 6, cv::Size(331, 97)), 0, 0.01, "331 x 97");
  // Fewer features than found: OpenCV's strongest are kept, ties by its own rule.
  expectOpenCvsKeypoints(blobs(80, 7), 100, 0.02, "the strongest 100");
}

TEST(SiftDetection, DescriptorsFromTheSharedScaleSpaceEqualDetectAndComputes) {
  if (!siftDetectionAvailable()) GTEST_SKIP() << "no AVX2 and FMA here, or AVX-512";
  for (unsigned seed : {3u, 4u}) {
    const cv::Mat image = blobs(15.0 * seed, seed);
    std::vector<cv::KeyPoint> reference_keypoints, keypoints;
    cv::Mat reference, descriptors;
    cv::SIFT::create(2000, 3, 0.02)
        ->detectAndCompute(image, cv::noArray(), reference_keypoints, reference);
    siftDetectAndCompute(image, 2000, 0.02, &keypoints, &descriptors);
    ASSERT_EQ(keypoints.size(), reference_keypoints.size());
    ASSERT_EQ(descriptors.size(), reference.size());
    cv::Mat differs;
    cv::compare(descriptors, reference, differs, cv::CMP_NE);
    EXPECT_EQ(cv::countNonZero(differs), 0) << "seed " << seed;
  }
}

TEST(SiftDetection, RefusesWhatItCannotDetectOn) {
  if (!siftDetectionAvailable()) GTEST_SKIP() << "no AVX2 and FMA here, or AVX-512";
  EXPECT_THROW(siftDetectionScaleSpace(cv::Mat()), Error);
  EXPECT_THROW(siftDetectionScaleSpace(cv::Mat(50, 50, CV_32F, cv::Scalar(0))), Error);
  // A flat image has no extrema.
  const cv::Mat flat(120, 160, CV_8U, cv::Scalar(90));
  EXPECT_TRUE(siftKeypoints(siftDetectionScaleSpace(flat), 0, 0.02).empty());
  // Too small for one octave: no keypoints, as in OpenCV.
  EXPECT_TRUE(
      siftKeypoints(siftDetectionScaleSpace(cv::Mat(1, 1, CV_8U, cv::Scalar(7))), 0, 0.02).empty());
}

}  // namespace
}  // namespace pnpba
