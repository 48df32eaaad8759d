#include "pnpba/features/matching.h"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <future>
#include <iterator>
#include <opencv2/features2d.hpp>

#include "pnpba/core/error.h"

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

// Hamming distance of two 32-byte ORB descriptors. Compiled twice: with the POPCNT
// instruction where the CPU has it (chosen at run time), and portable.
__attribute__((target("popcnt"))) int hamming32Popcnt(const uint64_t* a, const uint64_t* b) {
  return __builtin_popcountll(a[0] ^ b[0]) + __builtin_popcountll(a[1] ^ b[1]) +
         __builtin_popcountll(a[2] ^ b[2]) + __builtin_popcountll(a[3] ^ b[3]);
}
int hamming32Portable(const uint64_t* a, const uint64_t* b) {
  return __builtin_popcountll(a[0] ^ b[0]) + __builtin_popcountll(a[1] ^ b[1]) +
         __builtin_popcountll(a[2] ^ b[2]) + __builtin_popcountll(a[3] ^ b[3]);
}

// The two nearest rows of `train` for rows [begin, end) of `query` (32-byte descriptors).
template <int (*Distance)(const uint64_t*, const uint64_t*)>
void twoNearest(const cv::Mat& query, const cv::Mat& train, int begin, int end,
                std::vector<std::vector<cv::DMatch>>* out) {
  for (int q = begin; q < end; ++q) {
    const auto* a = query.ptr<uint64_t>(q);
    int best = INT_MAX, second = INT_MAX, best_idx = -1, second_idx = -1;
    for (int t = 0; t < train.rows; ++t) {
      const int d = Distance(a, train.ptr<uint64_t>(t));
      if (d < best) {
        second = best, second_idx = best_idx;
        best = d, best_idx = t;
      } else if (d < second) {
        second = d, second_idx = t;
      }
    }
    auto& list = (*out)[q];
    if (best_idx >= 0) list.emplace_back(q, best_idx, static_cast<float>(best));
    if (second_idx >= 0) list.emplace_back(q, second_idx, static_cast<float>(second));
  }
}

// Brute-force two nearest neighbours of every query descriptor, on two threads (the
// machine's two cores). 32-byte descriptors use the POPCNT kernel; others go to BFMatcher.
std::vector<std::vector<cv::DMatch>> twoNearestNeighbours(const cv::Mat& query,
                                                          const cv::Mat& train) {
  std::vector<std::vector<cv::DMatch>> out(query.rows);
  if (query.type() == CV_32F) {  // SIFT: Euclidean distance
    cv::BFMatcher(cv::NORM_L2).knnMatch(query, train, out, 2);
    return out;
  }
  if (query.cols != 32 || train.cols != 32 || query.type() != CV_8U || train.type() != CV_8U ||
      !query.isContinuous() || !train.isContinuous()) {
    cv::BFMatcher(cv::NORM_HAMMING).knnMatch(query, train, out, 2);
    return out;
  }
  static const bool has_popcnt = __builtin_cpu_supports("popcnt");
  auto run = [&](int begin, int end) {
    if (has_popcnt) {
      twoNearest<hamming32Popcnt>(query, train, begin, end, &out);
    } else {
      twoNearest<hamming32Portable>(query, train, begin, end, &out);
    }
  };
  const int half = query.rows / 2;
  auto second = std::async(std::launch::async, run, half, query.rows);
  run(0, half);
  second.get();
  return out;
}

}  // namespace

std::vector<cv::DMatch> matchDescriptors(const cv::Mat& descriptors1, const cv::Mat& descriptors2,
                                         const MatchOptions& options) {
  const std::string problem = options.validate();
  if (!problem.empty()) throw Error(problem);
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
      for (auto& list : twoNearestNeighbours(descriptors1, descriptors2)) {
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
      for (const auto& pair : twoNearestNeighbours(descriptors1, descriptors2)) {
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
