// pairBinsAvx2 (pair_bins.h): pairBins on four pairs at once. Every lane repeats the scalar
// function's operations in its order: dot products and norms as ((x x' + y y') + z z'), Eigen's
// cross product, each division and square root as one IEEE operation, and no fused multiply-add
// (this file is built with -mavx2 alone and -ffp-contract=off). Lanes the scalar function
// settles by a special case (a zero-length line or cross product, an angle within 1e-6 of a bin
// edge or with both arguments zero) are returned in the mask for it.
#include <immintrin.h>

#include "pair_bins.h"

namespace pnpba {

namespace {

struct V3 {
  __m256d x, y, z;
};

__m256d dot(const V3& a, const V3& b) {
  return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(a.x, b.x), _mm256_mul_pd(a.y, b.y)),
                       _mm256_mul_pd(a.z, b.z));
}

V3 cross(const V3& a, const V3& b) {
  return {_mm256_sub_pd(_mm256_mul_pd(a.y, b.z), _mm256_mul_pd(a.z, b.y)),
          _mm256_sub_pd(_mm256_mul_pd(a.z, b.x), _mm256_mul_pd(a.x, b.z)),
          _mm256_sub_pd(_mm256_mul_pd(a.x, b.y), _mm256_mul_pd(a.y, b.x))};
}

V3 select(__m256d mask, const V3& if_set, const V3& if_clear) {
  return {_mm256_blendv_pd(if_clear.x, if_set.x, mask),
          _mm256_blendv_pd(if_clear.y, if_set.y, mask),
          _mm256_blendv_pd(if_clear.z, if_set.z, mask)};
}

V3 gather(const double* const p[4]) {
  return {_mm256_set_pd(p[3][0], p[2][0], p[1][0], p[0][0]),
          _mm256_set_pd(p[3][1], p[2][1], p[1][1], p[0][1]),
          _mm256_set_pd(p[3][2], p[2][2], p[1][2], p[0][2])};
}

V3 broadcast(const double* p) {
  return {_mm256_set1_pd(p[0]), _mm256_set1_pd(p[1]), _mm256_set1_pd(p[2])};
}

__m256d absolute(__m256d a) { return _mm256_andnot_pd(_mm256_set1_pd(-0.0), a); }

// clampedBin on four values: floor, then 0..10.
__m128i clampedBins(__m256d bin) {
  const __m128i b = _mm256_cvttpd_epi32(_mm256_floor_pd(bin));
  return _mm_min_epi32(_mm_max_epi32(b, _mm_setzero_si128()), _mm_set1_epi32(10));
}

}  // namespace

int pairBinsAvx2(const double* p1, const double* n1, const double* const p2[4],
                 const double* const n2[4], PairBins out[4]) {
  const V3 a = broadcast(p1), na = broadcast(n1), b = gather(p2), nb = gather(n2);
  V3 d{_mm256_sub_pd(b.x, a.x), _mm256_sub_pd(b.y, a.y), _mm256_sub_pd(b.z, a.z)};
  const __m256d zero = _mm256_setzero_pd();
  const __m256d length = _mm256_sqrt_pd(dot(d, d));
  const __m256d cos1 = _mm256_div_pd(dot(na, d), length);
  const __m256d cos2 = _mm256_div_pd(dot(nb, d), length);
  const __m256d abs1 = absolute(cos1), abs2 = absolute(cos2);
  const __m256d swap = _mm256_cmp_pd(abs1, abs2, _CMP_LT_OQ);
  const __m256d reversible = _mm256_cmp_pd(abs1, abs2, _CMP_NEQ_UQ);
  const V3 u = select(swap, nb, na), other = select(swap, na, nb);
  // -d as Eigen negates: the sign flipped (0 - x would turn -0 into +0).
  const __m256d sign = _mm256_set1_pd(-0.0);
  const V3 negated{_mm256_xor_pd(d.x, sign), _mm256_xor_pd(d.y, sign), _mm256_xor_pd(d.z, sign)};
  d = select(swap, negated, d);
  V3 v = cross(d, u);
  const __m256d v_norm = _mm256_sqrt_pd(dot(v, v));
  v = {_mm256_div_pd(v.x, v_norm), _mm256_div_pd(v.y, v_norm), _mm256_div_pd(v.z, v_norm)};
  const V3 w = cross(u, v);
  const __m256d phi = _mm256_blendv_pd(cos1, _mm256_xor_pd(cos2, sign), swap);
  const __m256d alpha = dot(v, other);
  const __m256d y = dot(w, other), x = dot(u, other);

  // fastAngleBin, lane by lane as angle_bin.h writes it.
  const __m256d ax = absolute(x), ay = absolute(y);
  const __m256d x_bigger = _mm256_cmp_pd(ax, ay, _CMP_GT_OQ);
  const __m256d big = _mm256_blendv_pd(ay, ax, x_bigger),
                small = _mm256_blendv_pd(ax, ay, x_bigger);
  const __m256d z = _mm256_div_pd(small, big), z2 = _mm256_mul_pd(z, z);
  auto step = [&](__m256d acc, double c) {
    return _mm256_add_pd(_mm256_mul_pd(acc, z2), _mm256_set1_pd(c));
  };
  __m256d t = _mm256_set1_pd(-0.0040732905484800602);
  t = step(t, 0.021946545624836764);
  t = step(t, -0.056063087000463752);
  t = step(t, 0.096562502668578049);
  t = step(t, -0.13915799995588585);
  t = step(t, 0.19948508569705256);
  t = step(t, -0.33330106645107571);
  t = step(t, 0.99999943683630388);
  t = _mm256_mul_pd(t, z);
  t = _mm256_blendv_pd(t, _mm256_sub_pd(_mm256_set1_pd(M_PI / 2), t),
                       _mm256_cmp_pd(ay, ax, _CMP_GT_OQ));
  t = _mm256_blendv_pd(t, _mm256_sub_pd(_mm256_set1_pd(M_PI), t),
                       _mm256_cmp_pd(x, zero, _CMP_LT_OQ));
  t = _mm256_blendv_pd(t, _mm256_xor_pd(t, sign), _mm256_cmp_pd(y, zero, _CMP_LT_OQ));
  const __m256d scaled =
      _mm256_div_pd(_mm256_mul_pd(_mm256_set1_pd(11.0), _mm256_add_pd(t, _mm256_set1_pd(M_PI))),
                    _mm256_set1_pd(2.0 * M_PI));
  const __m256d below = _mm256_floor_pd(scaled);
  const __m256d margin = _mm256_set1_pd(1e-6);
  const __m256d near_edge =
      _mm256_or_pd(_mm256_cmp_pd(_mm256_sub_pd(scaled, below), margin, _CMP_LT_OQ),
                   _mm256_cmp_pd(_mm256_sub_pd(_mm256_add_pd(below, _mm256_set1_pd(1.0)), scaled),
                                 margin, _CMP_LT_OQ));
  // Left to the scalar function: the special cases, and anything not a number.
  const __m256d scalar =
      _mm256_or_pd(_mm256_or_pd(_mm256_cmp_pd(length, zero, _CMP_EQ_OQ),
                                _mm256_cmp_pd(v_norm, zero, _CMP_EQ_OQ)),
                   _mm256_or_pd(_mm256_or_pd(_mm256_cmp_pd(big, zero, _CMP_EQ_OQ), near_edge),
                                _mm256_cmp_pd(scaled, scaled, _CMP_UNORD_Q)));
  const __m128i theta = _mm_min_epi32(
      _mm_max_epi32(_mm256_cvttpd_epi32(below), _mm_setzero_si128()), _mm_set1_epi32(10));
  const __m256d half = _mm256_set1_pd(0.5), eleven = _mm256_set1_pd(11.0),
                one = _mm256_set1_pd(1.0);
  const __m128i alpha_bin =
      clampedBins(_mm256_mul_pd(_mm256_mul_pd(eleven, _mm256_add_pd(alpha, one)), half));
  const __m128i phi_bin =
      clampedBins(_mm256_mul_pd(_mm256_mul_pd(eleven, _mm256_add_pd(phi, one)), half));
  alignas(16) int th[4], al[4], ph[4];
  _mm_store_si128(reinterpret_cast<__m128i*>(th), theta);
  _mm_store_si128(reinterpret_cast<__m128i*>(al), alpha_bin);
  _mm_store_si128(reinterpret_cast<__m128i*>(ph), phi_bin);
  const int left = _mm256_movemask_pd(scalar);
  const int rev = _mm256_movemask_pd(reversible);
  for (int k = 0; k < 4; ++k) {
    if (left & (1 << k)) continue;
    out[k] = {th[k], 11 + al[k], 22 + ph[k], (rev & (1 << k)) != 0};
  }
  return left;
}

}  // namespace pnpba
