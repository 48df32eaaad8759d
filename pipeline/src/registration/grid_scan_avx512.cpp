#include <immintrin.h>

#include "grid_scan.h"

namespace pnpba {

size_t scanRunAvx512(const double* xs, const double* ys, const double* zs, const int* ids, int from,
                     int to, double x, double y, double z, double r2, double* distance2, int* id,
                     size_t kept) {
  const __m512d x8 = _mm512_set1_pd(x), y8 = _mm512_set1_pd(y), z8 = _mm512_set1_pd(z);
  const __m512d r8 = _mm512_set1_pd(r2);
  for (int t = from; t < to; t += 8) {
    // The last step reads only the run's remaining candidates.
    const __mmask8 in_run = to - t >= 8 ? 0xff : static_cast<__mmask8>((1u << (to - t)) - 1);
    const __m512d dx = _mm512_sub_pd(_mm512_maskz_loadu_pd(in_run, xs + t), x8);
    const __m512d dy = _mm512_sub_pd(_mm512_maskz_loadu_pd(in_run, ys + t), y8);
    const __m512d dz = _mm512_sub_pd(_mm512_maskz_loadu_pd(in_run, zs + t), z8);
    const __m512d d = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy)),
                                    _mm512_mul_pd(dz, dz));
    const __mmask8 near = _mm512_mask_cmp_pd_mask(in_run, d, r8, _CMP_LT_OQ);
    _mm512_mask_compressstoreu_pd(distance2 + kept, near, d);
    _mm256_mask_compressstoreu_epi32(id + kept, near, _mm256_maskz_loadu_epi32(in_run, ids + t));
    kept += static_cast<size_t>(__builtin_popcount(near));
  }
  return kept;
}

}  // namespace pnpba
