#include "two_nearest_kernels.h"

#include <immintrin.h>

#include <cfloat>
#include <climits>
#include <cmath>

namespace pnpba::kernels {

namespace {

// Hamming distance of two 32-byte descriptors. Compiled twice: with the POPCNT instruction where
// the CPU has it (chosen at run time), and portable.
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

template <int (*Distance)(const uint64_t*, const uint64_t*)>
void twoNearest(const cv::Mat& query, const cv::Mat& train, int begin, int end, Neighbours* out) {
  for (int q = begin; q < end; ++q) {
    const auto* a = query.ptr<uint64_t>(q);
    TwoNearest n;
    for (int t = 0; t < train.rows; ++t) n.offer(Distance(a, train.ptr<uint64_t>(t)), t);
    n.appendTo(q, &(*out)[q]);
  }
}

// The rows after the last whole block of eight, one by one, then the query's two into its list.
void finishRow(const cv::Mat& query, const cv::Mat& train, int q, TwoNearest* n, Neighbours* out) {
  static const bool has_popcnt = __builtin_cpu_supports("popcnt");
  const auto* a = query.ptr<uint64_t>(q);
  for (int t = train.rows & ~7; t < train.rows; ++t) {
    const auto* b = train.ptr<uint64_t>(t);
    n->offer(has_popcnt ? hamming32Popcnt(a, b) : hamming32Portable(a, b), t);
  }
  n->appendTo(q, &(*out)[q]);
}

// GCC 12's own intrinsics start some results from an undefined register, which
// -Wmaybe-uninitialized reports inside its headers; nothing here reads an undefined value.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

// ---- AVX2: bits counted per byte by a 16-entry table (one shuffle per nibble), summed over the
// four words (at most 32 per byte), then per row by a sum of absolute differences against zero.

__attribute__((target("avx2"))) inline __m256i bitsPerByte(__m256i v) {
  const __m256i table = _mm256_setr_epi8(0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4,  //
                                         0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4);
  const __m256i nibble = _mm256_set1_epi8(0x0f);
  const __m256i low = _mm256_and_si256(v, nibble);
  const __m256i high = _mm256_and_si256(_mm256_srli_epi16(v, 4), nibble);
  return _mm256_add_epi8(_mm256_shuffle_epi8(table, low), _mm256_shuffle_epi8(table, high));
}

// Distances of four rows (one 64-bit lane each) to a query: words[w] holds word w of the four.
__attribute__((target("avx2"))) inline __m256i fourDistances(const __m256i (&words)[4],
                                                             const __m256i (&query)[4]) {
  __m256i bytes = bitsPerByte(_mm256_xor_si256(words[0], query[0]));
  for (int w = 1; w < 4; ++w) {
    bytes = _mm256_add_epi8(bytes, bitsPerByte(_mm256_xor_si256(words[w], query[w])));
  }
  return _mm256_sad_epu8(bytes, _mm256_setzero_si256());
}

// Offers the block's eight rows in order, only when one is nearer than the second nearest so far
// (after the first rows most blocks offer none), so the result is the scalar scan's exactly.
__attribute__((target("avx2"))) inline void offerEight(__m256i first4, __m256i last4, int first_row,
                                                       TwoNearest* n) {
  const __m256i second = _mm256_set1_epi64x(n->second);
  const __m256i nearer =
      _mm256_or_si256(_mm256_cmpgt_epi64(second, first4), _mm256_cmpgt_epi64(second, last4));
  if (_mm256_testz_si256(nearer, nearer)) return;
  alignas(32) int64_t d[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(d), first4);
  _mm256_store_si256(reinterpret_cast<__m256i*>(d + 4), last4);
  for (int k = 0; k < 8; ++k) n->offer(static_cast<int>(d[k]), first_row + k);
}

// Queries [q, q + K) against every whole block, each loaded block serving the K of them.
template <int K>
__attribute__((target("avx2"))) inline void scanBlocksAvx2(const cv::Mat& query, int q,
                                                           const std::vector<uint64_t>& blocks,
                                                           int n8, TwoNearest* n) {
  __m256i rows[K][4];
  for (int k = 0; k < K; ++k) {
    const auto* row = query.ptr<uint64_t>(q + k);
    for (int w = 0; w < 4; ++w) rows[k][w] = _mm256_set1_epi64x(static_cast<int64_t>(row[w]));
  }
  for (int t = 0; t < n8; t += 8) {
    const uint64_t* block = blocks.data() + 4 * static_cast<size_t>(t);
    __m256i first[4], last[4];
    for (int w = 0; w < 4; ++w) {
      first[w] = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(block + 8 * w));
      last[w] = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(block + 8 * w + 4));
    }
    for (int k = 0; k < K; ++k) {
      offerEight(fourDistances(first, rows[k]), fourDistances(last, rows[k]), t, &n[k]);
    }
  }
}

// ---- AVX-512 with VPOPCNTDQ: eight rows per register, counted by one instruction per word.

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

template <int K>
__attribute__((target("avx512f,avx512vpopcntdq"))) inline void scanBlocksAvx512(
    const cv::Mat& query, int q, const std::vector<uint64_t>& blocks, int n8, TwoNearest* n) {
  __m512i rows[K][4];
  for (int k = 0; k < K; ++k) {
    const auto* row = query.ptr<uint64_t>(q + k);
    for (int w = 0; w < 4; ++w) rows[k][w] = _mm512_set1_epi64(static_cast<int64_t>(row[w]));
  }
  for (int t = 0; t < n8; t += 8) {
    const uint64_t* block = blocks.data() + 4 * static_cast<size_t>(t);
    __m512i words[4];
    for (int w = 0; w < 4; ++w) words[w] = _mm512_loadu_si512(block + 8 * w);
    for (int k = 0; k < K; ++k) offerBlock(blockDistances(words, rows[k]), t, &n[k]);
  }
}

// ---- Euclidean (SIFT). The two nearest so far, as BFMatcher's knnMatch finds them: it compares
// the rounded distances, so two squared distances whose square roots round to one float tie
// there, and the first row keeps its place. A squared distance at or above the second nearest's
// is passed over (its root cannot be smaller); others are offered by their root.
struct TwoNearestL2 {
  float best = FLT_MAX, best_squared = FLT_MAX, second = FLT_MAX, second_squared = FLT_MAX;
  int best_idx = -1, second_idx = -1;
  void offer(float squared, int t) {
    if (squared >= second_squared) return;
    const float distance = std::sqrt(squared);
    if (distance < best) {
      second = best, second_squared = best_squared, second_idx = best_idx;
      best = distance, best_squared = squared, best_idx = t;
    } else if (distance < second) {
      second = distance, second_squared = squared, second_idx = t;
    }
  }
  void appendTo(int q, std::vector<cv::DMatch>* list) const {
    if (best_idx >= 0) list->emplace_back(q, best_idx, best);
    if (second_idx >= 0) list->emplace_back(q, second_idx, second);
  }
};

__attribute__((target("avx2"))) inline int32_t sumOfLanes(__m256i v) {
  __m128i four = _mm_add_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
  four = _mm_add_epi32(four, _mm_shuffle_epi32(four, 0x4E));  // lanes 2, 3 onto 0, 1
  return _mm_cvtsi128_si32(_mm_add_epi32(four, _mm_shuffle_epi32(four, 0xB1)));
}

// Squared distances of K query rows to one train row, 16 elements a step: the differences
// (-255..255) as 16-bit integers, squared and summed in pairs into 32-bit lanes by one
// multiply-add. Each loaded train chunk serves the K queries. Every sum is exact, and below 2^24
// (128 x 255^2), so exact as a float too: BFMatcher's value.
template <int K>
__attribute__((target("avx2"))) inline void squaredDistancesAvx2(const int16_t* const (&a)[K],
                                                                 const int16_t* b,
                                                                 float (&out)[K]) {
  __m256i sum[K];
  for (int q = 0; q < K; ++q) sum[q] = _mm256_setzero_si256();
  for (int k = 0; k < 128; k += 16) {
    const __m256i chunk = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(b + k));
    for (int q = 0; q < K; ++q) {
      const __m256i d =
          _mm256_sub_epi16(chunk, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(a[q] + k)));
      sum[q] = _mm256_add_epi32(sum[q], _mm256_madd_epi16(d, d));
    }
  }
  for (int q = 0; q < K; ++q) out[q] = static_cast<float>(sumOfLanes(sum[q]));
}

// Query rows [q, q + K) against every train row, in row order for each.
template <int K>
__attribute__((target("avx2"))) inline void l2StepAvx2(const cv::Mat& query, const cv::Mat& train,
                                                       int q, Neighbours* out) {
  const int16_t* a[K];
  for (int k = 0; k < K; ++k) a[k] = query.ptr<int16_t>(q + k);
  TwoNearestL2 n[K];
  float squared[K];
  for (int t = 0; t < train.rows; ++t) {
    squaredDistancesAvx2<K>(a, train.ptr<int16_t>(t), squared);
    for (int k = 0; k < K; ++k) n[k].offer(squared[k], t);
  }
  for (int k = 0; k < K; ++k) n[k].appendTo(q + k, &(*out)[q + k]);
}

__attribute__((target("avx512f"))) inline float squaredDistanceAvx512(const __m512 (&a)[8],
                                                                      const float* b) {
  __m512 acc = _mm512_setzero_ps();
  for (int k = 0; k < 8; ++k) {
    const __m512 d = _mm512_sub_ps(_mm512_loadu_ps(b + 16 * k), a[k]);
    acc = _mm512_fmadd_ps(d, d, acc);
  }
  return _mm512_reduce_add_ps(acc);
}

}  // namespace

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

void hammingScalar(const cv::Mat& query, const cv::Mat& train, int begin, int end,
                   Neighbours* out) {
  static const bool has_popcnt = __builtin_cpu_supports("popcnt");
  if (has_popcnt) {
    twoNearest<hamming32Popcnt>(query, train, begin, end, out);
  } else {
    twoNearest<hamming32Portable>(query, train, begin, end, out);
  }
}

// One query per step on AVX2: the table lookups keep its sixteen registers busy, and a block
// loaded for two or four queries spilled them (textbook pair, 1500 x 1500: 1.5-1.8 ms for one,
// 1.8-2.0 for two or four).
__attribute__((target("avx2"))) void hammingAvx2(const cv::Mat& query, const cv::Mat& train,
                                                 const std::vector<uint64_t>& blocks, int begin,
                                                 int end, Neighbours* out) {
  const int n8 = train.rows & ~7;
  for (int q = begin; q < end; ++q) {
    TwoNearest n[1];
    scanBlocksAvx2<1>(query, q, blocks, n8, n);
    finishRow(query, train, q, &n[0], out);
  }
}

// Four queries per step on AVX-512, each loaded block serving the four.
__attribute__((target("avx512f,avx512vpopcntdq"))) void hammingAvx512(
    const cv::Mat& query, const cv::Mat& train, const std::vector<uint64_t>& blocks, int begin,
    int end, Neighbours* out) {
  const int n8 = train.rows & ~7;
  constexpr int kQueries = 4;
  int q = begin;
  for (; q + kQueries <= end; q += kQueries) {
    TwoNearest n[kQueries];
    scanBlocksAvx512<kQueries>(query, q, blocks, n8, n);
    for (int k = 0; k < kQueries; ++k) finishRow(query, train, q + k, &n[k], out);
  }
  for (; q < end; ++q) {
    TwoNearest n[1];
    scanBlocksAvx512<1>(query, q, blocks, n8, n);
    finishRow(query, train, q, &n[0], out);
  }
}

__attribute__((target("avx2"))) void l2Avx2(const cv::Mat& query, const cv::Mat& train, int begin,
                                            int end, Neighbours* out) {
  constexpr int kQueries = 4;
  int q = begin;
  for (; q + kQueries <= end; q += kQueries) l2StepAvx2<kQueries>(query, train, q, out);
  for (; q < end; ++q) l2StepAvx2<1>(query, train, q, out);
}

__attribute__((target("avx512f"))) void l2Avx512(const cv::Mat& query, const cv::Mat& train,
                                                 int begin, int end, Neighbours* out) {
  for (int q = begin; q < end; ++q) {
    const float* a = query.ptr<float>(q);
    __m512 rows[8];
    for (int k = 0; k < 8; ++k) rows[k] = _mm512_loadu_ps(a + 16 * k);
    TwoNearestL2 n;
    for (int t = 0; t < train.rows; ++t)
      n.offer(squaredDistanceAvx512(rows, train.ptr<float>(t)), t);
    n.appendTo(q, &(*out)[q]);
  }
}

#pragma GCC diagnostic pop

}  // namespace pnpba::kernels
