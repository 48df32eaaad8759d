// ORB's levels as tasks of their own (orb_levels.h) must give cv::ORB's keypoints and descriptors
// to the bit, in cv::ORB's order, whatever the image, its size, the levels, the scale factor and
// the feature count: the pipeline's answers rest on them.
#include "orb_levels.h"

#include <gtest/gtest.h>
#include <oneapi/tbb/global_control.h>

#include <filesystem>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

namespace pnpba {
namespace {

Features openCvOrb(const cv::Mat& image, const OrbOptions& o) {
  Features f;
  cv::ORB::create(o.num_features, o.scale_factor, o.levels, 31, 0, 2, cv::ORB::HARRIS_SCORE, 31,
                  o.fast_threshold)
      ->detectAndCompute(image, cv::noArray(), f.keypoints, f.descriptors);
  return f;
}

void expectOpenCvsOrb(const cv::Mat& image, const OrbOptions& o, const std::string& what) {
  const Features reference = openCvOrb(image, o);
  const Features ours = orbByLevel(image, o);
  ASSERT_EQ(ours.keypoints.size(), reference.keypoints.size()) << what;
  for (size_t i = 0; i < ours.keypoints.size(); ++i) {
    const cv::KeyPoint& a = ours.keypoints[i];
    const cv::KeyPoint& b = reference.keypoints[i];
    ASSERT_TRUE(a.pt == b.pt && a.size == b.size && a.angle == b.angle &&
                a.response == b.response && a.octave == b.octave && a.class_id == b.class_id)
        << what << ": keypoint " << i << " at (" << a.pt.x << ", " << a.pt.y << ") level "
        << a.octave << " against (" << b.pt.x << ", " << b.pt.y << ") level " << b.octave;
  }
  ASSERT_EQ(ours.descriptors.size(), reference.descriptors.size()) << what;
  if (!ours.keypoints.empty()) {
    EXPECT_EQ(cv::norm(ours.descriptors, reference.descriptors, cv::NORM_HAMMING), 0) << what;
  }
}

OrbOptions pnpbaOrb() { return OrbOptions{}; }  // 1500 features on 4 levels at 1.2

cv::Mat noiseImage(cv::Size size, unsigned seed, double blur) {
  cv::Mat noise(size, CV_8U);
  cv::theRNG().state = seed;
  cv::randu(noise, 0, 256);
  cv::GaussianBlur(noise, noise, cv::Size(), blur);
  cv::normalize(noise, noise, 0, 255, cv::NORM_MINMAX);
  return noise;
}

TEST(OrbLevels, EqualOpenCvsOrbOnTheProjectsPair) {
  for (const char* name : {"1.png", "2.png"}) {
    const std::string path = std::string(PNPBA_SOURCE_DIR) + "/data/images/" + name;
    const cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
    ASSERT_FALSE(image.empty()) << path;
    expectOpenCvsOrb(image, pnpbaOrb(), path);  // colour, converted as cv::ORB converts it
    cv::Mat grey;
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
    expectOpenCvsOrb(grey, pnpbaOrb(), path + " grey");
  }
}

TEST(OrbLevels, EqualOpenCvsOrbOnTheSharedImages) {
  const std::string shared = PNPBA_SHARED_DATA;
  if (!std::filesystem::exists(shared + "/slambook_ch7/1.png")) GTEST_SKIP() << "no shared data";
  for (const char* folder : {"tum_fr1_desk/rgb", "tum_fr3_cabinet_keyframes/rgb"}) {
    int taken = 0;
    for (const auto& entry : std::filesystem::directory_iterator(shared + "/" + folder)) {
      if (taken++ == 3) break;
      const cv::Mat image = cv::imread(entry.path().string(), cv::IMREAD_COLOR);
      ASSERT_FALSE(image.empty()) << entry.path();
      expectOpenCvsOrb(image, pnpbaOrb(), entry.path().string());
    }
  }
  expectOpenCvsOrb(cv::imread(shared + "/slambook_ch7/1.png", cv::IMREAD_COLOR), pnpbaOrb(),
                   "slambook_ch7/1.png");
}

TEST(OrbLevels, EqualOpenCvsOrbAtOtherSizesLevelsScalesAndCounts) {
  // Odd sizes (each level's size rounded from a float quotient), many levels and coarse scales
  // (level sizes down to a few pixels, below ORB's border), and counts that leave a level none.
  int case_number = 0;
  for (const cv::Size size : {cv::Size(640, 480), cv::Size(333, 251), cv::Size(97, 1201)}) {
    for (const auto& [levels, scale, features] :
         {std::tuple{4, 1.2f, 1500}, std::tuple{8, 1.2f, 500}, std::tuple{1, 1.2f, 1000},
          std::tuple{8, 1.1f, 3000}, std::tuple{6, 2.0f, 300}, std::tuple{5, 1.5f, 8}}) {
      OrbOptions o;
      o.levels = levels;
      o.scale_factor = scale;
      o.num_features = features;
      const cv::Mat image = noiseImage(size, 11 + case_number, 1.5 + case_number % 3);
      expectOpenCvsOrb(image, o,
                       "case " + std::to_string(case_number) + ": " + std::to_string(size.width) +
                           " x " + std::to_string(size.height) + ", " + std::to_string(levels) +
                           " levels at " + std::to_string(scale) + ", " + std::to_string(features) +
                           " features");
      ++case_number;
    }
  }
  // FAST's threshold passed on.
  OrbOptions o;
  o.fast_threshold = 7;
  expectOpenCvsOrb(noiseImage({640, 480}, 3, 3.0), o, "FAST threshold 7");
  // An image with nothing to find.
  expectOpenCvsOrb(cv::Mat(480, 640, CV_8U, cv::Scalar(90)), pnpbaOrb(), "a flat image");
}

TEST(OrbLevels, TheSameOnOneThreadAsOnTwo) {
  const cv::Mat image = noiseImage({640, 480}, 5, 2.0);
  auto detectOn = [&](int threads) {
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    return orbByLevel(image, pnpbaOrb());
  };
  const Features one = detectOn(1), two = detectOn(2);
  ASSERT_EQ(one.keypoints.size(), two.keypoints.size());
  ASSERT_GT(one.keypoints.size(), 1000u);
  for (size_t i = 0; i < one.keypoints.size(); ++i) {
    EXPECT_EQ(one.keypoints[i].pt, two.keypoints[i].pt);
    EXPECT_EQ(one.keypoints[i].response, two.keypoints[i].response);
  }
  EXPECT_EQ(cv::norm(one.descriptors, two.descriptors, cv::NORM_HAMMING), 0);
}

}  // namespace
}  // namespace pnpba
