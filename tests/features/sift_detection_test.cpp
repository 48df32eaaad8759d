// SIFT detection on the descriptors' scale space against OpenCV's detect, every keypoint field to
// the bit: on the shared real images (colour, grey, and shrunk as the SIFT retry shrinks them),
// on made-up textures turned every way, at other contrast thresholds and feature counts, and on
// a small image; the descriptors from the shared scale space equal detectAndCompute's.
#include "sift_detection.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

#include "pnpba/core/error.h"

namespace pnpba {
namespace {

std::string sharedImage(const std::string& relative) {
  return std::string(PNPBA_SHARED_DATA) + "/" + relative;
}

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
  std::vector<std::string> names = {"slambook_ch7/1.png", "slambook_ch7/2.png"};
  if (!std::filesystem::exists(sharedImage(names[0]))) GTEST_SKIP() << "no shared data";
  for (const char* folder : {"tum_fr1_desk/rgb", "tum_fr3_cabinet_keyframes/rgb"}) {
    const std::string path = sharedImage(folder);
    if (!std::filesystem::exists(path)) continue;
    int taken = 0;
    for (const auto& entry : std::filesystem::directory_iterator(path)) {
      names.push_back(std::string(folder) + "/" + entry.path().filename().string());
      if (++taken == 3) break;
    }
  }
  for (const std::string& name : names) {
    const cv::Mat colour = cv::imread(sharedImage(name), cv::IMREAD_COLOR);
    ASSERT_FALSE(colour.empty()) << name;
    cv::Mat grey, shrunk;
    cv::cvtColor(colour, grey, cv::COLOR_BGR2GRAY);
    expectOpenCvsKeypoints(colour, 1500, 0.04, name + " (colour)");
    expectOpenCvsKeypoints(grey, 0, 0.02, name + " (grey, every keypoint)");
    // The SIFT retry's input: the image shrunk by 2 / 0.85, by area.
    cv::resize(colour, shrunk, cv::Size(272, 204), 0, 0, cv::INTER_AREA);
    expectOpenCvsKeypoints(shrunk, 3000, 0.02, name + " (shrunk)");
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
