#include "pnpba/features/matching.h"

#include <immintrin.h>

#include <algorithm>
#include <cfloat>
#include <climits>
#include <cmath>
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

// The two nearest rows found so far; `offer` keeps the first of equal distances, as a scan in
// row order does.
struct TwoNearest {
  int best = INT_MAX, second = INT_MAX, best_idx = -1, second_idx = -1;
  void offer(int d, int t) {
    if (d < best) {
      second = best, second_idx = best_idx;
      best = d, best_idx = t;
    } else if (d < second) {
      second = d, second_idx = t;
    }
  }
  void appendTo(int q, std::vector<cv::DMatch>* list) const {
    if (best_idx >= 0) list->emplace_back(q, best_idx, static_cast<float>(best));
    if (second_idx >= 0) list->emplace_back(q, second_idx, static_cast<float>(second));
  }
};

// The two nearest rows of `train` for rows [begin, end) of `query` (32-byte descriptors).
template <int (*Distance)(const uint64_t*, const uint64_t*)>
void twoNearest(const cv::Mat& query, const cv::Mat& train, int begin, int end,
                std::vector<std::vector<cv::DMatch>>* out) {
  for (int q = begin; q < end; ++q) {
    const auto* a = query.ptr<uint64_t>(q);
    TwoNearest n;
    for (int t = 0; t < train.rows; ++t) n.offer(Distance(a, train.ptr<uint64_t>(t)), t);
    n.appendTo(q, &(*out)[q]);
  }
}

// Train rows in blocks of eight, 64-bit word by word: a block holds word 0 of its eight rows,
// then word 1, 2 and 3 (256 bytes), so that one register holds one word of eight rows and the
// eight distances to a query add up lane by lane, each in its row's lane. Rows past the last
// whole block are left to the scalar kernel.
std::vector<uint64_t> wordMajorBlocks(const cv::Mat& train) {
  const int blocks = train.rows / 8;
  std::vector<uint64_t> out(static_cast<size_t>(blocks) * 32);
  for (int r = 0; r < 8 * blocks; ++r) {
    const auto* row = train.ptr<uint64_t>(r);
    uint64_t* block = out.data() + static_cast<size_t>(r / 8) * 32;
    for (int w = 0; w < 4; ++w) block[8 * w + r % 8] = row[w];
  }
  return out;
}

// The same on AVX-512 with VPOPCNTDQ: eight train rows per step for four queries at once (each
// loaded word of the train serves the four), from wordMajorBlocks. Rows are offered in order, and
// only when one of the eight is nearer than the second nearest so far (after the first rows,
// most steps offer none), so the result is the scalar scan's exactly.
// GCC 12's own intrinsics start some results from an undefined register, which
// -Wmaybe-uninitialized reports inside its headers; nothing here reads an undefined value.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
__attribute__((target("avx512f,avx512vpopcntdq"))) inline void offerBlock(__m512i distances,
                                                                          int first_row,
                                                                          TwoNearest* n) {
  if (_mm512_cmplt_epi64_mask(distances, _mm512_set1_epi64(n->second)) == 0) return;
  alignas(64) int64_t d[8];
  _mm512_store_si512(d, distances);
  for (int k = 0; k < 8; ++k) n->offer(static_cast<int>(d[k]), first_row + k);
}

__attribute__((target("avx512f,avx512vpopcntdq"))) inline __m512i blockDistances(
    const __m512i (&words)[4], const __m512i (&query)[4]) {
  __m512i count[4];
  for (int w = 0; w < 4; ++w) count[w] = _mm512_popcnt_epi64(_mm512_xor_si512(words[w], query[w]));
  return _mm512_add_epi64(_mm512_add_epi64(count[0], count[1]),
                          _mm512_add_epi64(count[2], count[3]));
}

__attribute__((target("avx512f,avx512vpopcntdq"))) inline void broadcastWords(const uint64_t* row,
                                                                              __m512i (&words)[4]) {
  for (int w = 0; w < 4; ++w) words[w] = _mm512_set1_epi64(static_cast<int64_t>(row[w]));
}

// Queries [q, q + K) against every whole block, each loaded block serving the K of them.
template <int K>
__attribute__((target("avx512f,avx512vpopcntdq"))) inline void scanBlocks(
    const cv::Mat& query, int q, const std::vector<uint64_t>& blocks, int n8, TwoNearest* n) {
  __m512i rows[K][4];
  for (int k = 0; k < K; ++k) broadcastWords(query.ptr<uint64_t>(q + k), rows[k]);
  for (int t = 0; t < n8; t += 8) {
    const uint64_t* block = blocks.data() + 4 * static_cast<size_t>(t);
    __m512i words[4];
    for (int w = 0; w < 4; ++w) words[w] = _mm512_loadu_si512(block + 8 * w);
    for (int k = 0; k < K; ++k) offerBlock(blockDistances(words, rows[k]), t, &n[k]);
  }
}

__attribute__((target("avx512f,avx512vpopcntdq"))) void twoNearestAvx512(
    const cv::Mat& query, const cv::Mat& train, const std::vector<uint64_t>& blocks, int begin,
    int end, std::vector<std::vector<cv::DMatch>>* out) {
  const int n8 = train.rows & ~7;
  auto finish = [&](int q, TwoNearest* n) {
    const auto* a = query.ptr<uint64_t>(q);
    for (int t = n8; t < train.rows; ++t) n->offer(hamming32Popcnt(a, train.ptr<uint64_t>(t)), t);
    n->appendTo(q, &(*out)[q]);
  };
  constexpr int kQueries = 4;
  int q = begin;
  for (; q + kQueries <= end; q += kQueries) {
    TwoNearest n[kQueries];
    scanBlocks<kQueries>(query, q, blocks, n8, n);
    for (int k = 0; k < kQueries; ++k) finish(q + k, &n[k]);
  }
  for (; q < end; ++q) {
    TwoNearest n[1];
    scanBlocks<1>(query, q, blocks, n8, n);
    finish(q, &n[0]);
  }
}
#pragma GCC diagnostic pop

// SIFT: OpenCV's descriptors hold whole numbers (0-255), so every partial sum of squared
// differences is a whole number below 2^24 and exact in float whatever the order of summing:
// the squared distances are BFMatcher's to the bit, and the distances, sqrtf of them, too.
bool wholeNumbersBelow256(const cv::Mat& m) {
  for (int r = 0; r < m.rows; ++r) {
    const float* p = m.ptr<float>(r);
    for (int c = 0; c < m.cols; ++c) {
      if (!(p[c] >= 0.0f && p[c] <= 255.0f) || p[c] != std::nearbyint(p[c])) return false;
    }
  }
  return true;
}

// The two nearest train rows of 128-float query rows [begin, end), as BFMatcher's knnMatch
// finds them: it compares the rounded distances, so two squared distances whose square roots
// round to one float tie there, and the first row keeps its place. A row's squared distance at
// or above the second nearest's is passed over (its root cannot be smaller); others are
// offered by their root. (GCC 12's intrinsics: as for twoNearestAvx512 above.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
__attribute__((target("avx512f"))) void twoNearestL2Avx512(
    const cv::Mat& query, const cv::Mat& train, int begin, int end,
    std::vector<std::vector<cv::DMatch>>* out) {
  for (int q = begin; q < end; ++q) {
    const float* a = query.ptr<float>(q);
    __m512 qq[8];
    for (int k = 0; k < 8; ++k) qq[k] = _mm512_loadu_ps(a + 16 * k);
    // The two nearest so far: distance (what BFMatcher compares), its exact square, row.
    float best = FLT_MAX, best_squared = FLT_MAX, second = FLT_MAX, second_squared = FLT_MAX;
    int best_idx = -1, second_idx = -1;
    for (int t = 0; t < train.rows; ++t) {
      const float* b = train.ptr<float>(t);
      __m512 acc = _mm512_setzero_ps();
      for (int k = 0; k < 8; ++k) {
        const __m512 d = _mm512_sub_ps(_mm512_loadu_ps(b + 16 * k), qq[k]);
        acc = _mm512_fmadd_ps(d, d, acc);
      }
      const float squared = _mm512_reduce_add_ps(acc);
      if (squared >= second_squared) continue;
      const float distance = std::sqrt(squared);
      if (distance < best) {
        second = best, second_squared = best_squared, second_idx = best_idx;
        best = distance, best_squared = squared, best_idx = t;
      } else if (distance < second) {
        second = distance, second_squared = squared, second_idx = t;
      }
    }
    auto& list = (*out)[q];
    if (best_idx >= 0) list.emplace_back(q, best_idx, best);
    if (second_idx >= 0) list.emplace_back(q, second_idx, second);
  }
}
#pragma GCC diagnostic pop

// Brute-force two nearest neighbours of every query descriptor, on two threads (the
// machine's two cores). 32-byte descriptors use the AVX-512 or POPCNT kernel, whichever the CPU
// runs; SIFT's whole-number descriptors the AVX-512 L2 kernel where the CPU has it; others go to
// BFMatcher.
std::vector<std::vector<cv::DMatch>> twoNearestNeighbours(const cv::Mat& query,
                                                          const cv::Mat& train) {
  std::vector<std::vector<cv::DMatch>> out(query.rows);
  if (query.type() == CV_32F) {  // SIFT: Euclidean distance
    // 3000 x 3000 SIFT descriptors: 74-83 ms in BFMatcher (on both cores), 29 ms here.
    static const bool has_avx512 = __builtin_cpu_supports("avx512f");
    if (has_avx512 && query.cols == 128 && train.cols == 128 && train.type() == CV_32F &&
        wholeNumbersBelow256(query) && wholeNumbersBelow256(train)) {
      const int half = query.rows / 2;
      auto second = std::async(std::launch::async,
                               [&] { twoNearestL2Avx512(query, train, half, query.rows, &out); });
      twoNearestL2Avx512(query, train, 0, half, &out);
      second.get();
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
  static const bool has_popcnt = __builtin_cpu_supports("popcnt");
  static const bool has_avx512_popcnt =
      __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vpopcntdq");
  const bool vector = has_avx512_popcnt;
  const std::vector<uint64_t> blocks = vector ? wordMajorBlocks(train) : std::vector<uint64_t>();
  auto run = [&](int begin, int end) {
    if (vector) {
      twoNearestAvx512(query, train, blocks, begin, end, &out);
    } else if (has_popcnt) {
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
