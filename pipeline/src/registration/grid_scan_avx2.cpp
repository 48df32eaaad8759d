#include <immintrin.h>

#include <array>
#include <cstdint>

#include "grid_scan.h"

namespace pnpba {

namespace {

// For each 4-bit mask of kept lanes, the 32-bit lanes that move the kept doubles to the front
// (a double is two 32-bit lanes), and the bytes that move the kept 32-bit ids to the front: AVX2
// has no compressing store, so a permutation from a 16-entry table stands in for one.
struct CompressTables {
  std::array<std::array<int32_t, 8>, 16> doubles{};
  std::array<std::array<uint8_t, 16>, 16> ids{};
  CompressTables() {
    for (int mask = 0; mask < 16; ++mask) {
      int to = 0;
      for (int lane = 0; lane < 4; ++lane) {
        if (!(mask & (1 << lane))) continue;
        doubles[mask][2 * to] = 2 * lane;
        doubles[mask][2 * to + 1] = 2 * lane + 1;
        for (int b = 0; b < 4; ++b) ids[mask][4 * to + b] = static_cast<uint8_t>(4 * lane + b);
        ++to;
      }
    }
  }
};

const CompressTables& compressTables() {
  static const CompressTables tables;
  return tables;
}

}  // namespace

size_t scanRunAvx2(const double* xs, const double* ys, const double* zs, const int* ids, int from,
                   int to, double x, double y, double z, double r2, double* distance2, int* id,
                   size_t kept) {
  const CompressTables& tables = compressTables();
  const __m256d x4 = _mm256_set1_pd(x), y4 = _mm256_set1_pd(y), z4 = _mm256_set1_pd(z);
  const __m256d r4 = _mm256_set1_pd(r2);
  for (int t = from; t < to; t += 4) {
    // The last step reads only the run's remaining candidates (lanes past it load zeros and are
    // dropped from the mask).
    const int left = to - t;
    const int in_run = left >= 4 ? 0xf : (1 << left) - 1;
    const __m256i load = _mm256_setr_epi64x(-(in_run & 1), -((in_run >> 1) & 1),
                                            -((in_run >> 2) & 1), -((in_run >> 3) & 1));
    const __m256d dx = _mm256_sub_pd(_mm256_maskload_pd(xs + t, load), x4);
    const __m256d dy = _mm256_sub_pd(_mm256_maskload_pd(ys + t, load), y4);
    const __m256d dz = _mm256_sub_pd(_mm256_maskload_pd(zs + t, load), z4);
    const __m256d d = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)),
                                    _mm256_mul_pd(dz, dz));
    const int near = _mm256_movemask_pd(_mm256_cmp_pd(d, r4, _CMP_LT_OQ)) & in_run;
    // Four lanes are always written, the kept ones first: the output has room for four past
    // the last candidate (grid_scan.h).
    const __m256i move = _mm256_loadu_si256(
        reinterpret_cast<const __m256i*>(tables.doubles[static_cast<size_t>(near)].data()));
    _mm256_storeu_pd(distance2 + kept,
                     _mm256_castps_pd(_mm256_permutevar8x32_ps(_mm256_castpd_ps(d), move)));
    const __m128i four_ids =
        _mm_maskload_epi32(ids + t, _mm_setr_epi32(-(in_run & 1), -((in_run >> 1) & 1),
                                                   -((in_run >> 2) & 1), -((in_run >> 3) & 1)));
    const __m128i id_move = _mm_loadu_si128(
        reinterpret_cast<const __m128i*>(tables.ids[static_cast<size_t>(near)].data()));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(id + kept), _mm_shuffle_epi8(four_ids, id_move));
    kept += static_cast<size_t>(__builtin_popcount(static_cast<unsigned>(near)));
  }
  return kept;
}

}  // namespace pnpba
