// One SIFT descriptor with AVX2, in OpenCV 4.6's arithmetic (sift.simd.hpp, calcSIFTDescriptor):
// every float operation of OpenCV's is made here in the same order, so the descriptor is the
// same to the bit (sift_descriptors_test compares). OpenCV's AVX2 build lets the compiler fuse
// a multiply and an add where the product has no other use (the rotated coordinates, the
// Gaussian's exponent, the second norm); this file fuses those same ones by hand and is built
// with fusing off (CMakeLists.txt), so that no other rounds differently (fused any other way,
// about one element in 200 000 came out 1 off).
#include <immintrin.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <opencv2/core/hal/hal.hpp>

#include "sift_descriptors.h"

namespace pnpba::kernels {

namespace {

constexpr int kSpatial = 4;       // the descriptor's 4 x 4 cells
constexpr int kOrientations = 8;  // bins an orientation histogram
constexpr float kWidthFactor = 3.f;
constexpr float kClipRatio = 0.2f;
constexpr float kByteScale = 512.f;
// OpenCV's histogram has a cell of margin on each side (6 x 6 cells): a sample's weights go to
// the four cells around it, one of them possibly in the margin.
constexpr int kCells = (kSpatial + 2) * (kSpatial + 2);

// For a mask of eight lanes, the lanes that are set, first: a vector permutation packs the
// samples a window row keeps to the front.
struct PackLanes {
  alignas(32) int32_t index[256][8];
  PackLanes() {
    for (int mask = 0; mask < 256; ++mask) {
      int n = 0;
      for (int lane = 0; lane < 8; ++lane) {
        if (mask >> lane & 1) index[mask][n++] = lane;
      }
      while (n < 8) index[mask][n++] = 0;
    }
  }
};
const PackLanes kPack;

// Lane o set (orientation bin o of 0-7); row 8 has none set: bin 8, OpenCV's wrap-around bin,
// is kept apart.
struct OneLane {
  alignas(32) float mask[9][8];
  OneLane() {
    for (int o = 0; o < 9; ++o) {
      for (int lane = 0; lane < 8; ++lane) {
        const uint32_t bits = o == lane ? 0xffffffffu : 0u;
        std::memcpy(&mask[o][lane], &bits, sizeof bits);
      }
    }
  }
};
const OneLane kLane;

// The samples of the window: gradients, bin coordinates and Gaussian weight exponents, packed.
struct Samples {
  float *dx, *dy, *row_bin, *col_bin, *weight, *orientation, *magnitude;
  int count = 0;
};

// The columns j of window row i that can lie in the rotated square, a pixel wider on each side
// than the square itself: a sample is kept where both rotated coordinates, c = j cos - i sin and
// r = j sin + i cos, lie in (-2.5, 2.5) (bins (-1, 4) less 1.5). About half the window's
// pixels lie outside; the exact test still decides every pixel inside the span.
struct ColumnSpan {
  int first, last;
};
ColumnSpan rotatedSquareSpan(int i, float cos_t, float sin_t) {
  constexpr double kHalfSide = kSpatial / 2 + 0.5;
  double low = -1e9, high = 1e9;
  auto within = [&](double slope, double offset) {  // slope j + offset in (-kHalfSide, kHalfSide)
    if (std::abs(slope) < 1e-12) return;
    const double a = (-kHalfSide - offset) / slope, b = (kHalfSide - offset) / slope;
    low = std::max(low, std::min(a, b));
    high = std::min(high, std::max(a, b));
  };
  within(cos_t, -static_cast<double>(i) * sin_t);
  within(sin_t, static_cast<double>(i) * cos_t);
  return {static_cast<int>(std::floor(std::max(low, -1e9))) - 1,
          static_cast<int>(std::ceil(std::min(high, 1e9))) + 1};
}

// OpenCV's first pass: every pixel of the window (rows i, columns j within `radius` of the
// keypoint, inside the image less its border) whose rotated bin coordinates fall in (-1, 4).
__attribute__((target("avx2,fma"))) void gatherSamples(const cv::Mat& image, cv::Point centre,
                                                       int radius, float cos_t, float sin_t,
                                                       Samples* s) {
  const __m256 cos_v = _mm256_set1_ps(cos_t), sin_v = _mm256_set1_ps(sin_t);
  const __m256 lanes = _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256 minus_one = _mm256_set1_ps(-1.f), bins = _mm256_set1_ps(kSpatial);
  const __m256 half_bins = _mm256_set1_ps(kSpatial / 2), half = _mm256_set1_ps(0.5f);
  const __m256 exp_scale = _mm256_set1_ps(-1.f / (kSpatial * kSpatial * 0.5f));
  const __m256i lane_index = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  int k = 0;
  for (int i = -radius; i <= radius; ++i) {
    const int r = centre.y + i;
    if (r <= 0 || r >= image.rows - 1) continue;
    const ColumnSpan span = rotatedSquareSpan(i, cos_t, sin_t);
    const int j_first = std::max({-radius, 1 - centre.x, span.first});
    const int j_last = std::min({radius, image.cols - 2 - centre.x, span.last});
    const float* row = image.ptr<float>(r);
    const float* above = image.ptr<float>(r - 1);
    const float* below = image.ptr<float>(r + 1);
    const __m256 i_sin = _mm256_mul_ps(_mm256_set1_ps(static_cast<float>(i)), sin_v);
    const __m256 i_cos = _mm256_mul_ps(_mm256_set1_ps(static_cast<float>(i)), cos_v);
    for (int j = j_first; j <= j_last; j += 8) {
      const __m256 jv = _mm256_add_ps(_mm256_set1_ps(static_cast<float>(j)), lanes);
      const __m256 c_rot = _mm256_fmsub_ps(jv, cos_v, i_sin);
      const __m256 r_rot = _mm256_fmadd_ps(jv, sin_v, i_cos);
      const __m256 row_bin = _mm256_sub_ps(_mm256_add_ps(r_rot, half_bins), half);
      const __m256 col_bin = _mm256_sub_ps(_mm256_add_ps(c_rot, half_bins), half);
      const __m256 inside =
          _mm256_and_ps(_mm256_and_ps(_mm256_cmp_ps(row_bin, minus_one, _CMP_GT_OQ),
                                      _mm256_cmp_ps(row_bin, bins, _CMP_LT_OQ)),
                        _mm256_and_ps(_mm256_cmp_ps(col_bin, minus_one, _CMP_GT_OQ),
                                      _mm256_cmp_ps(col_bin, bins, _CMP_LT_OQ)));
      const int left = j_last - j + 1;
      int mask = _mm256_movemask_ps(inside);
      if (left < 8) mask &= (1 << left) - 1;
      if (mask == 0) continue;
      // Loads only of the columns this row has (the last block may be short).
      const __m256i in_row = _mm256_cmpgt_epi32(_mm256_set1_epi32(left), lane_index);
      const int c = centre.x + j;
      const __m256 dx = _mm256_sub_ps(_mm256_maskload_ps(row + c + 1, in_row),
                                      _mm256_maskload_ps(row + c - 1, in_row));
      const __m256 dy = _mm256_sub_ps(_mm256_maskload_ps(above + c, in_row),
                                      _mm256_maskload_ps(below + c, in_row));
      const __m256 w =
          _mm256_mul_ps(_mm256_fmadd_ps(c_rot, c_rot, _mm256_mul_ps(r_rot, r_rot)), exp_scale);
      const __m256i pack = _mm256_load_si256(reinterpret_cast<const __m256i*>(kPack.index[mask]));
      _mm256_storeu_ps(s->dx + k, _mm256_permutevar8x32_ps(dx, pack));
      _mm256_storeu_ps(s->dy + k, _mm256_permutevar8x32_ps(dy, pack));
      _mm256_storeu_ps(s->row_bin + k, _mm256_permutevar8x32_ps(row_bin, pack));
      _mm256_storeu_ps(s->col_bin + k, _mm256_permutevar8x32_ps(col_bin, pack));
      _mm256_storeu_ps(s->weight + k, _mm256_permutevar8x32_ps(w, pack));
      k += __builtin_popcount(static_cast<unsigned>(mask));
    }
  }
  s->count = k;
}

// The histogram: bins 0-7 of each of the 36 cells as one vector, bin 8 apart (OpenCV adds it
// to bin 0 at the end). OpenCV adds each sample's eight weights one float at a time; here the
// four cells around a run of samples stay in registers while the run lasts, and a sample adds
// to each a vector that is zero but in its two bins. Each bin thus receives the same non-zero
// terms in the same order (adding +0 changes no sum), and the sums are OpenCV's.
struct Histogram {
  alignas(32) float bins[kCells][8];
  float wrap[kCells];
};

// The four cells' sums from `cell` on back into the histogram.
__attribute__((target("avx2,fma"))) inline void store(int cell, __m256 c00, __m256 c01, __m256 c10,
                                                      __m256 c11, __m128 wrap, Histogram* h) {
  _mm256_store_ps(h->bins[cell], c00);
  _mm256_store_ps(h->bins[cell + 1], c01);
  _mm256_store_ps(h->bins[cell + kSpatial + 2], c10);
  _mm256_store_ps(h->bins[cell + kSpatial + 3], c11);
  alignas(16) float w[4];
  _mm_store_ps(w, wrap);
  h->wrap[cell] = w[0], h->wrap[cell + 1] = w[1];
  h->wrap[cell + kSpatial + 2] = w[2], h->wrap[cell + kSpatial + 3] = w[3];
}

// `sum` plus one sample's two terms, each in its bin's lane.
__attribute__((target("avx2,fma"))) inline __m256 addTerms(__m256 sum, __m256 lower_lane,
                                                           __m256 upper_lane,
                                                           const float* lower_term,
                                                           const float* upper_term) {
  return _mm256_add_ps(sum,
                       _mm256_or_ps(_mm256_and_ps(lower_lane, _mm256_broadcast_ss(lower_term)),
                                    _mm256_and_ps(upper_lane, _mm256_broadcast_ss(upper_term))));
}

__attribute__((target("avx2,fma"))) void accumulate(const Samples& s, float angle, Histogram* h) {
  std::memset(h, 0, sizeof *h);
  const __m256 angle_v = _mm256_set1_ps(angle);
  const __m256 bins_per_degree = _mm256_set1_ps(kOrientations / 360.f);
  const __m256i orientations = _mm256_set1_epi32(kOrientations), zero = _mm256_setzero_si256();
  const __m256i one = _mm256_set1_epi32(1), width = _mm256_set1_epi32(kSpatial + 2);
  const __m256i last_bin = _mm256_set1_epi32(kOrientations - 1);
  alignas(32) float terms[8][8];  // per sample of eight: its weight to each corner and bin
  alignas(32) int32_t cell[8], bin[8];
  alignas(16) float wrap_terms[8][4];
  int current = -1;
  __m256 c00 = _mm256_setzero_ps(), c01 = c00, c10 = c00, c11 = c00;
  __m128 wrap = _mm_setzero_ps();
  for (int first = 0; first < s.count; first += 8) {
    // OpenCV's vector part, eight samples at a time (the arrays hold eight floats past the end).
    __m256 rbin = _mm256_loadu_ps(s.row_bin + first);
    __m256 cbin = _mm256_loadu_ps(s.col_bin + first);
    __m256 obin = _mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(s.orientation + first), angle_v),
                                bins_per_degree);
    const __m256 mag =
        _mm256_mul_ps(_mm256_loadu_ps(s.magnitude + first), _mm256_loadu_ps(s.weight + first));
    const __m256 r_floor = _mm256_floor_ps(rbin), c_floor = _mm256_floor_ps(cbin);
    const __m256 o_floor = _mm256_floor_ps(obin);
    const __m256i r0 = _mm256_cvtps_epi32(r_floor), c0 = _mm256_cvtps_epi32(c_floor);
    __m256i o0 = _mm256_cvtps_epi32(o_floor);
    rbin = _mm256_sub_ps(rbin, r_floor);
    cbin = _mm256_sub_ps(cbin, c_floor);
    obin = _mm256_sub_ps(obin, o_floor);
    o0 = _mm256_blendv_epi8(o0, _mm256_add_epi32(o0, orientations), _mm256_cmpgt_epi32(zero, o0));
    o0 = _mm256_blendv_epi8(o0, _mm256_sub_epi32(o0, orientations),
                            _mm256_cmpgt_epi32(o0, last_bin));
    const __m256 r1 = _mm256_mul_ps(mag, rbin), r0w = _mm256_sub_ps(mag, r1);
    const __m256 rc11 = _mm256_mul_ps(r1, cbin), rc10 = _mm256_sub_ps(r1, rc11);
    const __m256 rc01 = _mm256_mul_ps(r0w, cbin), rc00 = _mm256_sub_ps(r0w, rc01);
    const __m256 rco111 = _mm256_mul_ps(rc11, obin), rco110 = _mm256_sub_ps(rc11, rco111);
    const __m256 rco101 = _mm256_mul_ps(rc10, obin), rco100 = _mm256_sub_ps(rc10, rco101);
    const __m256 rco011 = _mm256_mul_ps(rc01, obin), rco010 = _mm256_sub_ps(rc01, rco011);
    const __m256 rco001 = _mm256_mul_ps(rc00, obin), rco000 = _mm256_sub_ps(rc00, rco001);
    _mm256_store_ps(terms[0], rco000), _mm256_store_ps(terms[1], rco001);
    _mm256_store_ps(terms[2], rco010), _mm256_store_ps(terms[3], rco011);
    _mm256_store_ps(terms[4], rco100), _mm256_store_ps(terms[5], rco101);
    _mm256_store_ps(terms[6], rco110), _mm256_store_ps(terms[7], rco111);
    const __m256i cells = _mm256_add_epi32(_mm256_mullo_epi32(_mm256_add_epi32(r0, one), width),
                                           _mm256_add_epi32(c0, one));
    _mm256_store_si256(reinterpret_cast<__m256i*>(cell), cells);
    _mm256_store_si256(reinterpret_cast<__m256i*>(bin), o0);
    {
      // The terms for bin 8 (a sample in bin 7 gives its upper share to it), zero elsewhere,
      // transposed to one vector of the four cells a sample.
      const __m256 in_wrap = _mm256_castsi256_ps(_mm256_cmpeq_epi32(o0, last_bin));
      const __m256 e0 = _mm256_and_ps(in_wrap, rco001), e1 = _mm256_and_ps(in_wrap, rco011);
      const __m256 e2 = _mm256_and_ps(in_wrap, rco101), e3 = _mm256_and_ps(in_wrap, rco111);
      const __m256 t0 = _mm256_unpacklo_ps(e0, e1), t1 = _mm256_unpackhi_ps(e0, e1);
      const __m256 t2 = _mm256_unpacklo_ps(e2, e3), t3 = _mm256_unpackhi_ps(e2, e3);
      const __m256 u0 = _mm256_shuffle_ps(t0, t2, 0x44), u1 = _mm256_shuffle_ps(t0, t2, 0xEE);
      const __m256 u2 = _mm256_shuffle_ps(t1, t3, 0x44), u3 = _mm256_shuffle_ps(t1, t3, 0xEE);
      _mm_store_ps(wrap_terms[0], _mm256_castps256_ps128(u0));
      _mm_store_ps(wrap_terms[4], _mm256_extractf128_ps(u0, 1));
      _mm_store_ps(wrap_terms[1], _mm256_castps256_ps128(u1));
      _mm_store_ps(wrap_terms[5], _mm256_extractf128_ps(u1, 1));
      _mm_store_ps(wrap_terms[2], _mm256_castps256_ps128(u2));
      _mm_store_ps(wrap_terms[6], _mm256_extractf128_ps(u2, 1));
      _mm_store_ps(wrap_terms[3], _mm256_castps256_ps128(u3));
      _mm_store_ps(wrap_terms[7], _mm256_extractf128_ps(u3, 1));
    }
    // Then sample by sample, in OpenCV's order.
    const int n = std::min(8, s.count - first);
    for (int t = 0; t < n; ++t) {
      if (cell[t] != current) {
        if (current >= 0) store(current, c00, c01, c10, c11, wrap, h);
        current = cell[t];
        c00 = _mm256_load_ps(h->bins[current]);
        c01 = _mm256_load_ps(h->bins[current + 1]);
        c10 = _mm256_load_ps(h->bins[current + kSpatial + 2]);
        c11 = _mm256_load_ps(h->bins[current + kSpatial + 3]);
        wrap = _mm_setr_ps(h->wrap[current], h->wrap[current + 1], h->wrap[current + kSpatial + 2],
                           h->wrap[current + kSpatial + 3]);
      }
      const __m256 lower = _mm256_load_ps(kLane.mask[bin[t]]);
      const __m256 upper = _mm256_load_ps(kLane.mask[bin[t] + 1]);
      c00 = addTerms(c00, lower, upper, &terms[0][t], &terms[1][t]);
      c01 = addTerms(c01, lower, upper, &terms[2][t], &terms[3][t]);
      c10 = addTerms(c10, lower, upper, &terms[4][t], &terms[5][t]);
      c11 = addTerms(c11, lower, upper, &terms[6][t], &terms[7][t]);
      wrap = _mm_add_ps(wrap, _mm_load_ps(wrap_terms[t]));
    }
  }
  if (current >= 0) store(current, c00, c01, c10, c11, wrap, h);
}

}  // namespace

__attribute__((target("avx2,fma"))) void siftDescriptorAvx2(const cv::Mat& octave_image,
                                                            cv::Point2f point, float angle,
                                                            float scale, float* out,
                                                            SiftScratch* scratch) {
  const cv::Point centre(cvRound(point.x), cvRound(point.y));
  float cos_t = cosf(angle * static_cast<float>(CV_PI / 180));
  float sin_t = sinf(angle * static_cast<float>(CV_PI / 180));
  const float hist_width = kWidthFactor * scale;
  int radius = cvRound(hist_width * 1.4142135623730951f * (kSpatial + 1) * 0.5f);
  radius = std::min(
      radius,
      static_cast<int>(std::sqrt(static_cast<double>(octave_image.cols) * octave_image.cols +
                                 static_cast<double>(octave_image.rows) * octave_image.rows)));
  cos_t /= hist_width;
  sin_t /= hist_width;

  // Seven arrays of the window's pixels, each with eight floats to spare for whole vectors.
  const size_t stride = static_cast<size_t>(2 * radius + 1) * (2 * radius + 1) + 8;
  scratch->samples.resize(7 * stride);
  float* base = scratch->samples.data();
  Samples s{base,
            base + stride,
            base + 2 * stride,
            base + 3 * stride,
            base + 4 * stride,
            base + 5 * stride,
            base + 6 * stride};
  gatherSamples(octave_image, centre, radius, cos_t, sin_t, &s);
  cv::hal::fastAtan2(s.dy, s.dx, s.orientation, s.count, true);
  cv::hal::magnitude32f(s.dx, s.dy, s.magnitude, s.count);
  cv::hal::exp32f(s.weight, s.weight, s.count);

  Histogram h;
  accumulate(s, angle, &h);

  // OpenCV's finish: bin 8 onto bin 0 (bin 9 never receives), the norm (eight lanes of fused
  // multiply-adds, then their sum in the order of OpenCV's v_reduce_sum for AVX2), clipping at 0.2
  // of it, the norm again (one float at a time) and bytes.
  alignas(32) float raw[kSpatial * kSpatial * kOrientations];
  for (int i = 0; i < kSpatial; ++i) {
    for (int j = 0; j < kSpatial; ++j) {
      const int c = (i + 1) * (kSpatial + 2) + (j + 1);
      h.bins[c][0] += h.wrap[c];
      std::copy(h.bins[c], h.bins[c] + kOrientations, raw + (i * kSpatial + j) * kOrientations);
    }
  }
  constexpr int kLength = kSpatial * kSpatial * kOrientations;
  __m256 squares = _mm256_setzero_ps();
  for (int k = 0; k < kLength; k += 8) {
    const __m256 v = _mm256_load_ps(raw + k);
    squares = _mm256_fmadd_ps(v, v, squares);
  }
  squares = _mm256_hadd_ps(squares, squares);
  squares = _mm256_hadd_ps(squares, squares);
  const __m128 sum = _mm_add_ps(_mm256_castps256_ps128(squares), _mm256_extractf128_ps(squares, 1));
  const float threshold = std::sqrt(_mm_cvtss_f32(sum)) * kClipRatio;
  float norm2 = 0;
  for (int k = 0; k < kLength; ++k) {
    const float v = std::min(raw[k], threshold);
    raw[k] = v;
    norm2 = std::fma(v, v, norm2);
  }
  const float to_bytes = kByteScale / std::max(std::sqrt(norm2), FLT_EPSILON);
  for (int k = 0; k < kLength; ++k) out[k] = cv::saturate_cast<uchar>(raw[k] * to_bytes);
}

}  // namespace pnpba::kernels
