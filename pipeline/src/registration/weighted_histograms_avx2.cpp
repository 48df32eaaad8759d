#include <immintrin.h>

#include <cstddef>

#include "weighted_histograms.h"

namespace pnpba {

void weightedHistogramSumAvx2(const double* histograms, const int* index, const double* distance2,
                              int k, double* out) {
  // Bins 0-31 in eight registers, bin 32 alone.
  __m256d sum[8];
  for (__m256d& s : sum) s = _mm256_setzero_pd();
  double last = 0;
  for (int j = 0; j < k; ++j) {
    if (distance2[j] == 0.0) continue;
    const double w = 1.0 / distance2[j];
    const __m256d w4 = _mm256_set1_pd(w);
    const double* h = histograms + 33 * static_cast<size_t>(index[j]);
    for (int b = 0; b < 8; ++b) {
      sum[b] = _mm256_add_pd(sum[b], _mm256_mul_pd(w4, _mm256_loadu_pd(h + 4 * b)));
    }
    last = last + w * h[32];
  }
  for (int b = 0; b < 8; ++b) _mm256_storeu_pd(out + 4 * b, sum[b]);
  out[32] = last;
}

}  // namespace pnpba
