#include "pnpba/features/matching.h"

#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <opencv2/features2d.hpp>

#include "pnpba/core/error.h"
#include "two_nearest_kernels.h"

namespace pnpba {

const char* toString(MatchFilter filter) {
  switch (filter) {
    case MatchFilter::kTextbook:
      return "textbook";
    case MatchFilter::kRatio:
      return "ratio";
    case MatchFilter::kCrossCheck:
      return "cross-check";
  }
  return "?";
}

MatchFilter parseMatchFilter(const std::string& name) {
  for (MatchFilter f : {MatchFilter::kTextbook, MatchFilter::kRatio, MatchFilter::kCrossCheck}) {
    if (name == toString(f)) return f;
  }
  throw Error("unknown match filter '" + name + "' (expected textbook, ratio or cross-check)");
}

std::string MatchOptions::validate() const {
  if (!(ratio > 0 && ratio <= 1)) return "ratio must be in (0, 1]";
  if (max_distance < 0) return "max distance must be >= 0";
  return "";
}

namespace {

using kernels::Neighbours;

// SIFT: OpenCV's descriptors hold whole numbers (0-255), which the vector L2 kernels need.
// Truncation rather than std::nearbyint, a library call per value: the textbook pair's two 1500
// rows checked in 0.4 ms instead of 1.2.
bool wholeNumbersBelow256(const cv::Mat& m) {
  for (int r = 0; r < m.rows; ++r) {
    const float* p = m.ptr<float>(r);
    bool whole = true;
    for (int c = 0; c < m.cols; ++c) {
      // Out of range (NaN included) becomes 0.5, which is not whole; in range, truncation is
      // defined and gives the value back only for a whole number.
      const bool in_range = (p[c] >= 0.0f) & (p[c] <= 255.0f);
      const float v = in_range ? p[c] : 0.5f;
      whole &= static_cast<float>(static_cast<int>(v)) == v;
    }
    if (!whole) return false;
  }
  return true;
}

bool cpuHas(MatchKernel kernel) {
  static const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  static const bool avx512 = __builtin_cpu_supports("avx512f");
  static const bool avx512_popcount = avx512 && __builtin_cpu_supports("avx512vpopcntdq");
  switch (kernel) {
    case MatchKernel::kAvx512:
      return avx512_popcount;  // the L2 kernel needs avx512f alone, a subset
    case MatchKernel::kAvx2:
      return avx2;
    case MatchKernel::kFastest:
    case MatchKernel::kScalar:
      break;
  }
  return true;
}

MatchKernel fastestKernel() {
  for (MatchKernel k : {MatchKernel::kAvx512, MatchKernel::kAvx2}) {
    if (cpuHas(k)) return k;
  }
  return MatchKernel::kScalar;
}

// Query rows in chunks of 64 on TBB's workers, each row's neighbours its own: where the second
// core is shared with other work, halves left the pair waiting on the slower one; chunks go to
// whichever core is free.
template <typename Kernel>
void onEitherCore(int rows, const Kernel& kernel) {
  constexpr int kChunk = 64;
  tbb::parallel_for(0, (rows + kChunk - 1) / kChunk,
                    [&](int c) { kernel(c * kChunk, std::min(rows, (c + 1) * kChunk)); });
}

// Brute-force two nearest neighbours of every query descriptor. 32-byte descriptors and SIFT's
// whole-number ones go to the chosen vector kernel (3000 x 3000 SIFT descriptors: 74-83 ms in
// BFMatcher on both cores, 29 ms in the AVX-512 kernel); others to BFMatcher.
Neighbours twoNearestNeighbours(const cv::Mat& query, const cv::Mat& train, MatchKernel kernel) {
  Neighbours out(query.rows);
  if (query.type() == CV_32F) {  // SIFT: Euclidean distance
    const bool sift_like = query.cols == 128 && train.cols == 128 && train.type() == CV_32F &&
                           query.isContinuous() && train.isContinuous() &&
                           wholeNumbersBelow256(query) && wholeNumbersBelow256(train);
    if (sift_like && kernel == MatchKernel::kAvx512) {
      onEitherCore(query.rows, [&](int b, int e) { kernels::l2Avx512(query, train, b, e, &out); });
    } else if (sift_like && kernel == MatchKernel::kAvx2) {
      // As 16-bit integers (exact for whole numbers 0-255): 1500 x 1500 descriptors of the
      // textbook pair 7.0 -> 4.9 ms on both cores with the check below (pipeline_bench's
      // BM_SiftMatching).
      cv::Mat query16, train16;
      query.convertTo(query16, CV_16S);
      train.convertTo(train16, CV_16S);
      onEitherCore(query.rows,
                   [&](int b, int e) { kernels::l2Avx2(query16, train16, b, e, &out); });
    } else {
      cv::BFMatcher(cv::NORM_L2).knnMatch(query, train, out, 2);
    }
    return out;
  }
  if (query.cols != 32 || train.cols != 32 || query.type() != CV_8U || train.type() != CV_8U ||
      !query.isContinuous() || !train.isContinuous()) {
    cv::BFMatcher(cv::NORM_HAMMING).knnMatch(query, train, out, 2);
    return out;
  }
  if (kernel == MatchKernel::kScalar) {
    onEitherCore(query.rows,
                 [&](int b, int e) { kernels::hammingScalar(query, train, b, e, &out); });
    return out;
  }
  const std::vector<uint64_t> blocks = kernels::wordMajorBlocks(train);
  if (kernel == MatchKernel::kAvx512) {
    onEitherCore(query.rows,
                 [&](int b, int e) { kernels::hammingAvx512(query, train, blocks, b, e, &out); });
  } else {
    onEitherCore(query.rows,
                 [&](int b, int e) { kernels::hammingAvx2(query, train, blocks, b, e, &out); });
  }
  return out;
}

}  // namespace

bool hasMatchKernel(MatchKernel kernel) { return cpuHas(kernel); }

std::vector<cv::DMatch> matchDescriptors(const cv::Mat& descriptors1, const cv::Mat& descriptors2,
                                         const MatchOptions& options, MatchKernel kernel) {
  const std::string problem = options.validate();
  if (!problem.empty()) throw Error(problem);
  if (!cpuHas(kernel))
    throw Error(std::string("this CPU cannot run the matching kernel ") +
                (kernel == MatchKernel::kAvx512 ? "avx512" : "avx2"));
  if (kernel == MatchKernel::kFastest) kernel = fastestKernel();
  std::vector<cv::DMatch> kept;
  if (descriptors1.empty() || descriptors2.empty()) return kept;
  if (descriptors1.type() != descriptors2.type()) {
    throw Error("descriptors of different types cannot be matched");
  }
  const int norm = descriptors1.type() == CV_32F ? cv::NORM_L2 : cv::NORM_HAMMING;
  cv::BFMatcher matcher(norm, options.filter == MatchFilter::kCrossCheck);

  switch (options.filter) {
    case MatchFilter::kTextbook: {
      std::vector<cv::DMatch> all;
      for (auto& list : twoNearestNeighbours(descriptors1, descriptors2, kernel)) {
        if (!list.empty()) all.push_back(list[0]);
      }
      double min_dist = 10000;
      for (const cv::DMatch& m : all) min_dist = std::min<double>(min_dist, m.distance);
      for (const cv::DMatch& m : all) {
        if (m.distance <= std::max(2 * min_dist, 30.0)) kept.push_back(m);
      }
      break;
    }
    case MatchFilter::kRatio: {
      for (const auto& pair : twoNearestNeighbours(descriptors1, descriptors2, kernel)) {
        if (pair.size() == 2 && pair[0].distance < options.ratio * pair[1].distance) {
          kept.push_back(pair[0]);
        } else if (pair.size() == 1) {
          kept.push_back(pair[0]);
        }
      }
      break;
    }
    case MatchFilter::kCrossCheck:
      matcher.match(descriptors1, descriptors2, kept);
      break;
  }
  if (options.max_distance > 0) {
    kept.erase(
        std::remove_if(kept.begin(), kept.end(),
                       [&](const cv::DMatch& m) { return m.distance > options.max_distance; }),
        kept.end());
  }
  std::sort(kept.begin(), kept.end(),
            [](const cv::DMatch& a, const cv::DMatch& b) { return a.queryIdx < b.queryIdx; });
  return kept;
}

}  // namespace pnpba
