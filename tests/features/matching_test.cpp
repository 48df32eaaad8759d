// Descriptor matching filters against a brute-force reference computed here with std::bitset.
#include "pnpba/features/matching.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bitset>
#include <map>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <set>

#include "pnpba/core/error.h"
#include "pnpba/features/orb_features.h"

namespace pnpba {
namespace {

cv::Mat randomDescriptors(int rows, std::mt19937* rng) {
  cv::Mat d(rows, 32, CV_8U);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < 32; ++c) d.at<uint8_t>(r, c) = static_cast<uint8_t>(byte(*rng));
  return d;
}

// Flips `bits` distinct bits of row r.
void flipBits(cv::Mat* d, int r, int bits, std::mt19937* rng) {
  std::set<int> chosen;
  std::uniform_int_distribution<int> bit(0, 255);
  while (static_cast<int>(chosen.size()) < bits) chosen.insert(bit(*rng));
  for (int b : chosen) d->at<uint8_t>(r, b / 8) ^= static_cast<uint8_t>(1u << (b % 8));
}

int hamming(const cv::Mat& a, int ra, const cv::Mat& b, int rb) {
  int n = 0;
  for (int c = 0; c < 32; ++c)
    n += std::bitset<8>(a.at<uint8_t>(ra, c) ^ b.at<uint8_t>(rb, c)).count();
  return n;
}

struct Reference {
  int best = -1, best_distance = 1 << 30, second_distance = 1 << 30;
};

Reference nearest(const cv::Mat& d1, int r, const cv::Mat& d2) {
  Reference ref;
  for (int j = 0; j < d2.rows; ++j) {
    const int h = hamming(d1, r, d2, j);
    if (h < ref.best_distance) {
      ref.second_distance = ref.best_distance;
      ref.best_distance = h;
      ref.best = j;
    } else if (h < ref.second_distance) {
      ref.second_distance = h;
    }
  }
  return ref;
}

// Image 2 holds noisy copies of the first 60 descriptors of image 1 (5-40 flipped bits), two
// near-duplicates of descriptor 0 (ambiguous), and random rows.
class Matching : public ::testing::Test {
 protected:
  void SetUp() override {
    std::mt19937 rng(3);
    d1_ = randomDescriptors(100, &rng);
    d2_ = randomDescriptors(120, &rng);
    for (int i = 0; i < 60; ++i) {
      d1_.row(i).copyTo(d2_.row(i + 10));
      flipBits(&d2_, i + 10, 5 + (i * 7) % 36, &rng);
    }
    d1_.row(0).copyTo(d2_.row(0));
    flipBits(&d2_, 0, 6, &rng);
  }
  cv::Mat d1_, d2_;
};

TEST_F(Matching, RatioFilterKeepsExactlyTheUnambiguousNearestNeighbours) {
  MatchOptions o;
  o.filter = MatchFilter::kRatio;
  const auto matches = matchDescriptors(d1_, d2_, o);
  std::set<std::pair<int, int>> got;
  for (const cv::DMatch& m : matches) {
    got.insert({m.queryIdx, m.trainIdx});
    EXPECT_EQ(m.distance, hamming(d1_, m.queryIdx, d2_, m.trainIdx));
  }
  std::set<std::pair<int, int>> expected;
  for (int r = 0; r < d1_.rows; ++r) {
    const Reference ref = nearest(d1_, r, d2_);
    if (ref.best_distance < o.ratio * ref.second_distance) expected.insert({r, ref.best});
  }
  EXPECT_EQ(got, expected);
  EXPECT_GE(got.size(), 50u);  // most noisy copies survive
  for (size_t i = 1; i < matches.size(); ++i)
    EXPECT_LT(matches[i - 1].queryIdx, matches[i].queryIdx);
}

TEST_F(Matching, CrossCheckKeepsMutualNearestNeighbours) {
  MatchOptions o;
  o.filter = MatchFilter::kCrossCheck;
  std::set<std::pair<int, int>> got;
  for (const cv::DMatch& m : matchDescriptors(d1_, d2_, o)) got.insert({m.queryIdx, m.trainIdx});
  cv::Mat none;
  for (const auto& [q, t] : got) {
    EXPECT_EQ(nearest(d1_, q, d2_).best_distance, hamming(d1_, q, d2_, t));
    EXPECT_EQ(nearest(d2_, t, d1_).best_distance, hamming(d1_, q, d2_, t));
  }
  for (int i = 1; i < 60; ++i) EXPECT_TRUE(got.count({i, i + 10})) << "copy " << i;
}

TEST_F(Matching, TextbookRuleKeepsDistancesUpToTwiceTheMinimumOrThirty) {
  MatchOptions o;
  o.filter = MatchFilter::kTextbook;
  int min_distance = 1 << 30;
  for (int r = 0; r < d1_.rows; ++r)
    min_distance = std::min(min_distance, nearest(d1_, r, d2_).best_distance);
  const double limit = std::max(2.0 * min_distance, 30.0);
  int expected = 0;
  for (int r = 0; r < d1_.rows; ++r) expected += nearest(d1_, r, d2_).best_distance <= limit;
  const auto matches = matchDescriptors(d1_, d2_, o);
  EXPECT_EQ(static_cast<int>(matches.size()), expected);
  for (const cv::DMatch& m : matches) EXPECT_LE(m.distance, limit);
}

TEST_F(Matching, DistanceCapDropsFartherMatches) {
  MatchOptions o;
  o.max_distance = 20;
  for (const cv::DMatch& m : matchDescriptors(d1_, d2_, o)) EXPECT_LE(m.distance, 20);
}

// Many near-identical descriptors (few flipped bits of one base: small distances, many ties) at
// row counts around the matcher's blocks of eight: the nearest row (the first of equal ones)
// and whether it is strictly nearer than the second are the reference's at every count.
// Every kernel this CPU runs, each on its own (kFastest is one of them).
std::vector<MatchKernel> kernelsHere() {
  std::vector<MatchKernel> here;
  for (MatchKernel k : {MatchKernel::kAvx512, MatchKernel::kAvx2, MatchKernel::kScalar}) {
    if (hasMatchKernel(k)) here.push_back(k);
  }
  return here;
}

const char* nameOf(MatchKernel k) {
  return k == MatchKernel::kAvx512 ? "avx512" : k == MatchKernel::kAvx2 ? "avx2" : "scalar";
}

TEST(MatchingKernel, NearestAndSecondAgreeWithTheReferenceAtEveryRowCount) {
  ASSERT_TRUE(hasMatchKernel(MatchKernel::kScalar));
  for (MatchKernel kernel : kernelsHere()) {
    SCOPED_TRACE(nameOf(kernel));
    std::mt19937 rng(11);
    const cv::Mat base = randomDescriptors(1, &rng);
    auto noisyCopies = [&](int rows, int max_bits) {
      cv::Mat d(rows, 32, CV_8U);
      for (int r = 0; r < rows; ++r) {
        base.copyTo(d.row(r));
        flipBits(&d, r, static_cast<int>(rng() % (max_bits + 1)), &rng);
      }
      return d;
    };
    const cv::Mat queries = noisyCopies(40, 6);
    for (int rows : {1, 7, 8, 9, 15, 16, 17, 64, 123, 1003}) {
      const cv::Mat train = noisyCopies(rows, 12);
      MatchOptions textbook;  // every nearest row, distances here far below its limit of 30
      textbook.filter = MatchFilter::kTextbook;
      const auto nearest_rows = matchDescriptors(queries, train, textbook, kernel);
      ASSERT_EQ(static_cast<int>(nearest_rows.size()), queries.rows) << rows;
      MatchOptions strict;  // ratio 1: kept exactly when the nearest is strictly nearer
      strict.ratio = 1.0;
      std::set<int> kept;
      for (const cv::DMatch& m : matchDescriptors(queries, train, strict, kernel)) {
        kept.insert(m.queryIdx);
      }
      for (const cv::DMatch& m : nearest_rows) {
        const Reference ref = nearest(queries, m.queryIdx, train);
        EXPECT_EQ(m.trainIdx, ref.best) << rows << " rows, query " << m.queryIdx;
        EXPECT_EQ(m.distance, ref.best_distance);
        EXPECT_EQ(kept.count(m.queryIdx) == 1, ref.best_distance < ref.second_distance)
            << rows << " rows, query " << m.queryIdx;
      }
    }
  }
}

// Real ORB descriptors of the sample pair: every kernel gives the scalar kernel's matches, row
// and distance, through both filters.
TEST(MatchingKernel, EveryKernelMatchesTheSamplePairAsTheScalarOneDoes) {
  const std::string images = std::string(PNPBA_SOURCE_DIR) + "/data/images/";
  const Features f1 = detectOrb(cv::imread(images + "1.png"), OrbOptions{});
  const Features f2 = detectOrb(cv::imread(images + "2.png"), OrbOptions{});
  ASSERT_GT(f1.descriptors.rows, 500);
  MatchOptions textbook;
  textbook.filter = MatchFilter::kTextbook;
  for (const MatchOptions& o : {MatchOptions{}, textbook}) {
    const auto reference =
        matchDescriptors(f1.descriptors, f2.descriptors, o, MatchKernel::kScalar);
    ASSERT_GT(reference.size(), 100u);
    for (MatchKernel kernel : kernelsHere()) {
      const auto got = matchDescriptors(f1.descriptors, f2.descriptors, o, kernel);
      ASSERT_EQ(got.size(), reference.size()) << nameOf(kernel);
      for (size_t i = 0; i < got.size(); ++i) {
        EXPECT_EQ(got[i].queryIdx, reference[i].queryIdx) << nameOf(kernel);
        EXPECT_EQ(got[i].trainIdx, reference[i].trainIdx) << nameOf(kernel);
        EXPECT_EQ(got[i].distance, reference[i].distance) << nameOf(kernel);
      }
    }
  }
}

// A kernel the CPU lacks is refused with a message, never run.
TEST(MatchingKernel, AKernelTheCpuLacksIsRefused) {
  std::mt19937 rng(2);
  const cv::Mat d = randomDescriptors(20, &rng);
  for (MatchKernel kernel : {MatchKernel::kAvx512, MatchKernel::kAvx2}) {
    if (hasMatchKernel(kernel)) {
      EXPECT_EQ(matchDescriptors(d, d, MatchOptions{}, kernel).size(), 20u);
    } else {
      EXPECT_THROW(matchDescriptors(d, d, MatchOptions{}, kernel), Error);
    }
  }
}

// SIFT's float descriptors: the matches equal BFMatcher's (row and distance, to the bit), on
// descriptors with many near ties (small whole-number changes of one base vector, at row counts
// around the kernel's lanes), on real SIFT descriptors of the sample pair, and on descriptors that
// are not whole numbers (which BFMatcher itself matches).
void expectSameAsBfMatcher(const cv::Mat& queries, const cv::Mat& train, const std::string& what) {
  for (MatchKernel kernel : kernelsHere()) {
    SCOPED_TRACE(nameOf(kernel));
    std::vector<std::vector<cv::DMatch>> knn;
    cv::BFMatcher(cv::NORM_L2).knnMatch(queries, train, knn, 2);
    MatchOptions textbook;
    textbook.filter = MatchFilter::kTextbook;
    std::map<int, cv::DMatch> nearest;
    for (const cv::DMatch& m : matchDescriptors(queries, train, textbook, kernel)) {
      nearest[m.queryIdx] = m;
    }
    for (double ratio : {1.0, 0.8}) {
      MatchOptions o;
      o.ratio = ratio;
      std::set<int> kept;
      for (const cv::DMatch& m : matchDescriptors(queries, train, o, kernel))
        kept.insert(m.queryIdx);
      for (int q = 0; q < queries.rows; ++q) {
        const bool expected =
            knn[q].size() == 1 ||
            (knn[q].size() == 2 && knn[q][0].distance < ratio * knn[q][1].distance);
        EXPECT_EQ(kept.count(q) == 1, expected) << what << ", ratio " << ratio << ", query " << q;
      }
    }
    // The textbook filter keeps each query's nearest row within its distance limit.
    double min_distance = 1e300;
    for (const auto& list : knn) min_distance = std::min<double>(min_distance, list[0].distance);
    for (int q = 0; q < queries.rows; ++q) {
      const cv::DMatch& m = knn[q][0];
      if (m.distance > std::max(2 * min_distance, 30.0)) continue;
      ASSERT_EQ(nearest.count(q), 1u) << what << ", query " << q;
      EXPECT_EQ(nearest[q].trainIdx, m.trainIdx) << what << ", query " << q;
      EXPECT_EQ(nearest[q].distance, m.distance) << what << ", query " << q;
    }
  }
}

TEST(MatchingKernel, SiftDescriptorsMatchAsBfMatcherDoes) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> value(0, 255), change(-2, 2);
  cv::Mat base(1, 128, CV_32F);
  for (int c = 0; c < 128; ++c) base.at<float>(0, c) = static_cast<float>(value(rng));
  auto nearBase = [&](int rows) {
    cv::Mat d(rows, 128, CV_32F);
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < 128; ++c) {
        d.at<float>(r, c) = static_cast<float>(std::clamp(
            static_cast<int>(base.at<float>(0, c)) + (rng() % 4 == 0 ? change(rng) : 0), 0, 255));
      }
    }
    return d;
  };
  const cv::Mat queries = nearBase(50);
  for (int rows : {1, 2, 3, 17, 200}) expectSameAsBfMatcher(queries, nearBase(rows), "near ties");

  const std::string images = std::string(PNPBA_SOURCE_DIR) + "/data/images/";
  OrbOptions sift;
  sift.detector = Detector::kSift;
  sift.num_features = 1000;
  const Features f1 = detectOrb(cv::imread(images + "1.png"), sift);
  const Features f2 = detectOrb(cv::imread(images + "2.png"), sift);
  ASSERT_GT(f1.descriptors.rows, 500);
  expectSameAsBfMatcher(f1.descriptors, f2.descriptors, "SIFT on the sample pair");

  cv::Mat fractional = f2.descriptors * 0.37;  // not whole numbers: BFMatcher's own path
  expectSameAsBfMatcher(f1.descriptors * 0.37, fractional, "fractional");
  // Whole numbers past 255 (up to 51000, past 16 bits): outside the kernels' exact range, so
  // they too go to BFMatcher.
  cv::Mat large = f2.descriptors * 200;
  expectSameAsBfMatcher(f1.descriptors * 200, large, "whole numbers past 255");
}

TEST(MatchOptions, ValidateAndParseNameTheProblem) {
  MatchOptions o;
  o.ratio = 1.5;
  EXPECT_NE(o.validate(), "");
  EXPECT_EQ(MatchOptions{}.validate(), "");
  EXPECT_EQ(parseMatchFilter("cross-check"), MatchFilter::kCrossCheck);
  EXPECT_THROW(parseMatchFilter("nearest"), Error);
}

}  // namespace
}  // namespace pnpba
