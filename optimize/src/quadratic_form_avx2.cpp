// quadratic_form.h's kernels for AVX2, written with intrinsics: Eigen's generic products use only
// two-wide vectors on these sizes. Built with -mavx2, without -mfma and without contraction
// (optimize/CMakeLists.txt): every entry is fl(H + fl(fl(a0 b0) + fl(a1 b1))), the sum the
// generic code forms, so both builds give the same bits
// (QuadraticForm.Avx2KernelsEqualTheBaselineToTheBit).
#include <immintrin.h>

#include "quadratic_form_kernels.h"

namespace pnpba::internal::avx2 {

namespace {

// Rows 0-3 and 4-5 of a 6-vector.
struct Column6 {
  __m256d head;
  __m128d tail;
};

Column6 load6(const double* v) { return {_mm256_loadu_pd(v), _mm_loadu_pd(v + 4)}; }

// dst += a x + b y, or dst -= a x + b y (x and y broadcast): each entry
// fl(dst ± fl(fl(a x) + fl(b y))).
template <bool kSubtract>
void accumulateTwoProducts(const Column6& a, const Column6& b, double x, double y, double* dst) {
  const __m256d x4 = _mm256_set1_pd(x), y4 = _mm256_set1_pd(y);
  const __m256d head = _mm256_add_pd(_mm256_mul_pd(a.head, x4), _mm256_mul_pd(b.head, y4));
  const __m256d old_head = _mm256_loadu_pd(dst);
  _mm256_storeu_pd(dst, kSubtract ? _mm256_sub_pd(old_head, head) : _mm256_add_pd(old_head, head));
  const __m128d x2 = _mm256_castpd256_pd128(x4), y2 = _mm256_castpd256_pd128(y4);
  const __m128d tail = _mm_add_pd(_mm_mul_pd(a.tail, x2), _mm_mul_pd(b.tail, y2));
  const __m128d old_tail = _mm_loadu_pd(dst + 4);
  _mm_storeu_pd(dst + 4, kSubtract ? _mm_sub_pd(old_tail, tail) : _mm_add_pd(old_tail, tail));
}

// The point's 3 x 3 block and 3-vector: rows 0-1 two-wide, row 2 alone.
void addPointTerms(double w, const double* J_p, const double* e, double* H_pp, double* b_p) {
  // (w J_p)ᵀ: column k is row k of J_p (2 x 3, column-major) times w.
  const double p0[3] = {w * J_p[0], w * J_p[2], w * J_p[4]};
  const double p1[3] = {w * J_p[1], w * J_p[3], w * J_p[5]};
  const __m128d p0_head = _mm_loadu_pd(p0), p1_head = _mm_loadu_pd(p1);
  for (int j = 0; j < 3; ++j) {
    const double x = J_p[2 * j], y = J_p[2 * j + 1];
    double* col = H_pp + 3 * j;
    const __m128d sum =
        _mm_add_pd(_mm_mul_pd(p0_head, _mm_set1_pd(x)), _mm_mul_pd(p1_head, _mm_set1_pd(y)));
    _mm_storeu_pd(col, _mm_add_pd(_mm_loadu_pd(col), sum));
    col[2] = col[2] + (p0[2] * x + p1[2] * y);
  }
  const __m128d sum =
      _mm_add_pd(_mm_mul_pd(p0_head, _mm_set1_pd(e[0])), _mm_mul_pd(p1_head, _mm_set1_pd(e[1])));
  _mm_storeu_pd(b_p, _mm_sub_pd(_mm_loadu_pd(b_p), sum));
  b_p[2] = b_p[2] - (p0[2] * e[0] + p1[2] * e[1]);
}

}  // namespace

void addPointPoseQuadraticForm(double w, const double* J_p, const double* J_c, const double* e,
                               double* H_pp, double* b_p, double* H_cc, double* b_c, double* H_cp) {
  addPointTerms(w, J_p, e, H_pp, b_p);
  // (w J_c)ᵀ's two columns: the rows of J_c (2 x 6, column-major) times w.
  double c0[6], c1[6];
  for (int j = 0; j < 6; ++j) c0[j] = w * J_c[2 * j], c1[j] = w * J_c[2 * j + 1];
  const Column6 a = load6(c0), b = load6(c1);
  for (int j = 0; j < 6; ++j)
    accumulateTwoProducts<false>(a, b, J_c[2 * j], J_c[2 * j + 1], H_cc + 6 * j);
  accumulateTwoProducts<true>(a, b, e[0], e[1], b_c);
  for (int j = 0; j < 3; ++j)
    accumulateTwoProducts<false>(a, b, J_p[2 * j], J_p[2 * j + 1], H_cp + 6 * j);
}

void addPointQuadraticForm(double w, const double* J_p, const double* e, double* H_pp,
                           double* b_p) {
  addPointTerms(w, J_p, e, H_pp, b_p);
}

}  // namespace pnpba::internal::avx2
