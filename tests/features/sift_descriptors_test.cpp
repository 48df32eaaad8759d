// The SIFT descriptor kernel against OpenCV's detectAndCompute, to the bit where OpenCV runs its
// AVX2 build (against its AVX-512 build: at most one element in 10 000 off, by one): on the shared
// real images (colour and grey, whole and shrunk as the SIFT retry shrinks them), on a made-up
// texture turned to every orientation, with keypoints by the border, and through detectOrb.
#include "sift_descriptors.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

#include "pnpba/core/error.h"
#include "pnpba/features/orb_features.h"
#include "sift_test_images.h"

namespace pnpba {
namespace {

// OpenCV's own keypoints and descriptors (its defaults but the counts the pipeline uses).
struct OpenCvSift {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
};
OpenCvSift openCvSift(const cv::Mat& image, int features, double contrast) {
  OpenCvSift s;
  cv::SIFT::create(features, 3, contrast)
      ->detectAndCompute(image, cv::noArray(), s.keypoints, s.descriptors);
  return s;
}

// The kernel's descriptors of OpenCV's keypoints equal OpenCV's, every element.
void expectOpenCvsDescriptors(const cv::Mat& image, int features, double contrast,
                              const std::string& what) {
  const OpenCvSift reference = openCvSift(image, features, contrast);
  ASSERT_GT(reference.keypoints.size(), 50u) << what;
  const cv::Mat ours = siftDescriptors(image, reference.keypoints);
  ASSERT_EQ(ours.type(), reference.descriptors.type()) << what;
  ASSERT_EQ(ours.size(), reference.descriptors.size()) << what;
  cv::Mat differs;
  cv::compare(ours, reference.descriptors, differs, cv::CMP_NE);
  const int differing = cv::countNonZero(differs);
  if (!cv::checkHardwareSupport(CV_CPU_AVX512_SKX)) {
    EXPECT_EQ(differing, 0) << what << ": " << reference.keypoints.size() << " keypoints";
  } else {
    // Where the CPU has AVX-512, OpenCV's descriptors come from its AVX-512 build, whose sums
    // round in another order than the AVX2 one the kernel follows: an element in 10 000 may
    // land on the next whole number, never further.
    EXPECT_LE(differing, ours.total() / 10000)
        << what << ": " << reference.keypoints.size() << " keypoints";
    EXPECT_LE(cv::norm(ours, reference.descriptors, cv::NORM_INF), 1.0) << what;
  }
  // Whole numbers 0-255, as the matching kernels need.
  double low = 0, high = 0;
  cv::minMaxLoc(ours, &low, &high);
  EXPECT_GE(low, 0) << what;
  EXPECT_LE(high, 255) << what;
  EXPECT_GT(high, 0) << what;
}

// A texture of blurred random blobs, turned by `degrees` about its centre: keypoints at every
// orientation and scale, some by the border.
cv::Mat madeUpTexture(double degrees, unsigned seed) {
  std::mt19937 random(seed);
  cv::Mat noise(300, 400, CV_8U);
  cv::randu(noise, 0, 256);
  cv::theRNG().state = seed;
  cv::Mat blurred;
  cv::GaussianBlur(noise, blurred, cv::Size(), 2.5);
  cv::normalize(blurred, blurred, 0, 255, cv::NORM_MINMAX);
  const cv::Mat turn =
      cv::getRotationMatrix2D(cv::Point2f(200, 150), degrees, 1.0 + 0.1 * (random() % 3));
  cv::Mat turned;
  cv::warpAffine(blurred, turned, turn, blurred.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return turned;
}

TEST(SiftDescriptors, EqualOpenCvsOnTheSharedImages) {
  if (!fastSiftDescriptorsAvailable()) GTEST_SKIP() << "no AVX2 and FMA here";
  const std::vector<testing::SiftTestImage> images =
      testing::sharedSiftTestImages({"tum_fr1_desk/rgb"});
  if (images.empty()) GTEST_SKIP() << "no shared data";
  EXPECT_GE(images.size(), 6u);
  for (const testing::SiftTestImage& t : images) {
    expectOpenCvsDescriptors(t.image, t.features, t.contrast, t.what);
  }
}

TEST(SiftDescriptors, EqualOpenCvsAtEveryOrientationAndByTheBorder) {
  if (!fastSiftDescriptorsAvailable()) GTEST_SKIP() << "no AVX2 and FMA here";
  for (int t = 0; t < 8; ++t) {
    const double degrees = 45.0 * t + 7.0;
    expectOpenCvsDescriptors(madeUpTexture(degrees, 11 + t), 3000, 0.02,
                             "texture turned " + std::to_string(degrees) + " deg");
  }
  // A small image: windows that the border cuts on every side.
  cv::Mat small;
  cv::resize(madeUpTexture(30, 5), small, cv::Size(96, 72), 0, 0, cv::INTER_AREA);
  const OpenCvSift reference = openCvSift(small, 500, 0.02);
  ASSERT_FALSE(reference.keypoints.empty());
  cv::Mat differs;
  cv::compare(siftDescriptors(small, reference.keypoints), reference.descriptors, differs,
              cv::CMP_NE);
  EXPECT_EQ(cv::countNonZero(differs), 0);
}

TEST(SiftDescriptors, NoKeypointsGiveNoRowsAndStrangeOctavesAreRefused) {
  if (!fastSiftDescriptorsAvailable()) GTEST_SKIP() << "no AVX2 and FMA here";
  const cv::Mat image = madeUpTexture(0, 3);
  const cv::Mat none = siftDescriptors(image, {});
  EXPECT_EQ(none.rows, 0);
  EXPECT_EQ(none.cols, 128);
  cv::KeyPoint odd(cv::Point2f(50, 50), 3.f, 10.f);
  odd.octave = (-2) & 255;  // octave -2: OpenCV never doubles twice
  EXPECT_THROW(siftDescriptors(image, {odd}), Error);
  odd.octave = 9;  // a 400 x 300 image has octaves -1 to 6
  EXPECT_THROW(siftDescriptors(image, {odd}), Error);
}

// detectOrb's SIFT (first octave -1, and 0 with a fraction as the retry uses it) keeps OpenCV's
// descriptors: the same rows as detectAndCompute on the image it was given.
TEST(SiftDescriptors, DetectOrbKeepsOpenCvsDescriptors) {
  const cv::Mat image = madeUpTexture(20, 9);
  OrbOptions o;
  o.detector = Detector::kSift;
  o.num_features = 1000;
  const Features whole = detectOrb(image, o);
  const OpenCvSift reference = openCvSift(image, 1000, o.sift_contrast_threshold);
  ASSERT_EQ(whole.keypoints.size(), reference.keypoints.size());
  cv::Mat differs;
  cv::compare(whole.descriptors, reference.descriptors, differs, cv::CMP_NE);
  EXPECT_EQ(cv::countNonZero(differs), 0);

  o.sift_first_octave = 0;
  o.sift_octave_fraction = 0.85;
  const Features shrunk = detectOrb(image, o);
  const double by = 2 / o.sift_octave_fraction;  // as detectSift shrinks it
  cv::Mat small;
  cv::resize(image, small, cv::Size(std::lround(image.cols / by), std::lround(image.rows / by)), 0,
             0, cv::INTER_AREA);
  const OpenCvSift shrunk_reference = openCvSift(small, 1000, o.sift_contrast_threshold);
  ASSERT_EQ(shrunk.keypoints.size(), shrunk_reference.keypoints.size());
  cv::compare(shrunk.descriptors, shrunk_reference.descriptors, differs, cv::CMP_NE);
  EXPECT_EQ(cv::countNonZero(differs), 0);
}

}  // namespace
}  // namespace pnpba
