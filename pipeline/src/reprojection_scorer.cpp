#include "reprojection_scorer.h"

#include <immintrin.h>

#include <limits>

namespace pnpba {

namespace {

// The pose's numbers the kernels need: Eigen's quaternion rotation (Quaternion.h,
// _transformVector) is uv = 2 (q.vec x X), R X = X + w uv + q.vec x uv.
struct Pose {
  double qx, qy, qz, qw, tx, ty, tz;
  explicit Pose(const SE3Quat& T)
      : qx(T.rotation().x()),
        qy(T.rotation().y()),
        qz(T.rotation().z()),
        qw(T.rotation().w()),
        tx(T.translation().x()),
        ty(T.translation().y()),
        tz(T.translation().z()) {}
};

struct Intrinsics {
  double fx, fy, cx, cy;
};

// Pairs [begin, end) one at a time, in Eigen's order of operations.
void scoreScalar(const Pose& p, const Intrinsics& k, const double* x, const double* y,
                 const double* z, const double* u, const double* v, int begin, int end,
                 double* out) {
  for (int i = begin; i < end; ++i) {
    double uvx = p.qy * z[i] - p.qz * y[i];
    double uvy = p.qz * x[i] - p.qx * z[i];
    double uvz = p.qx * y[i] - p.qy * x[i];
    uvx += uvx, uvy += uvy, uvz += uvz;
    const double crx = p.qy * uvz - p.qz * uvy;
    const double cry = p.qz * uvx - p.qx * uvz;
    const double crz = p.qx * uvy - p.qy * uvx;
    const double Px = x[i] + p.qw * uvx + crx + p.tx;
    const double Py = y[i] + p.qw * uvy + cry + p.ty;
    const double Pz = z[i] + p.qw * uvz + crz + p.tz;
    const double du = k.fx * Px / Pz + k.cx - u[i];
    const double dv = k.fy * Py / Pz + k.cy - v[i];
    out[i] = Pz > 0 ? du * du + dv * dv : std::numeric_limits<double>::infinity();
  }
}

// a1 b2 - a2 b1, one component of a cross product.
__attribute__((target("avx2"))) inline __m256d cross(__m256d a1, __m256d b2, __m256d a2,
                                                     __m256d b1) {
  return _mm256_sub_pd(_mm256_mul_pd(a1, b2), _mm256_mul_pd(a2, b1));
}

// The same operations on four pairs per instruction (no FMA: "avx2" alone).
__attribute__((target("avx2"))) void scoreAvx2(const Pose& p, const Intrinsics& k, const double* x,
                                               const double* y, const double* z, const double* u,
                                               const double* v, int n, double* out) {
  const __m256d qx = _mm256_set1_pd(p.qx), qy = _mm256_set1_pd(p.qy), qz = _mm256_set1_pd(p.qz);
  const __m256d qw = _mm256_set1_pd(p.qw), tx = _mm256_set1_pd(p.tx), ty = _mm256_set1_pd(p.ty);
  const __m256d tz = _mm256_set1_pd(p.tz), fx = _mm256_set1_pd(k.fx), fy = _mm256_set1_pd(k.fy);
  const __m256d cx = _mm256_set1_pd(k.cx), cy = _mm256_set1_pd(k.cy);
  const __m256d zero = _mm256_setzero_pd();
  const __m256d inf = _mm256_set1_pd(std::numeric_limits<double>::infinity());
  const int n4 = n & ~3;
  for (int i = 0; i < n4; i += 4) {
    const __m256d X = _mm256_loadu_pd(x + i), Y = _mm256_loadu_pd(y + i);
    const __m256d Z = _mm256_loadu_pd(z + i);
    __m256d uvx = cross(qy, Z, qz, Y), uvy = cross(qz, X, qx, Z), uvz = cross(qx, Y, qy, X);
    uvx = _mm256_add_pd(uvx, uvx), uvy = _mm256_add_pd(uvy, uvy), uvz = _mm256_add_pd(uvz, uvz);
    const __m256d crx = cross(qy, uvz, qz, uvy), cry = cross(qz, uvx, qx, uvz);
    const __m256d crz = cross(qx, uvy, qy, uvx);
    const __m256d Px =
        _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(X, _mm256_mul_pd(qw, uvx)), crx), tx);
    const __m256d Py =
        _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(Y, _mm256_mul_pd(qw, uvy)), cry), ty);
    const __m256d Pz =
        _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(Z, _mm256_mul_pd(qw, uvz)), crz), tz);
    const __m256d du = _mm256_sub_pd(_mm256_add_pd(_mm256_div_pd(_mm256_mul_pd(fx, Px), Pz), cx),
                                     _mm256_loadu_pd(u + i));
    const __m256d dv = _mm256_sub_pd(_mm256_add_pd(_mm256_div_pd(_mm256_mul_pd(fy, Py), Pz), cy),
                                     _mm256_loadu_pd(v + i));
    const __m256d e2 = _mm256_add_pd(_mm256_mul_pd(du, du), _mm256_mul_pd(dv, dv));
    const __m256d in_front = _mm256_cmp_pd(Pz, zero, _CMP_GT_OQ);
    _mm256_storeu_pd(out + i, _mm256_blendv_pd(inf, e2, in_front));
  }
  scoreScalar(p, k, x, y, z, u, v, n4, n, out);
}

}  // namespace

ReprojectionScorer::ReprojectionScorer(const Correspondences& pairs, const PinholeCamera& camera)
    : fx_(camera.fx), fy_(camera.fy), cx_(camera.cx), cy_(camera.cy) {
  for (std::vector<double>* a : {&x_, &y_, &z_, &u_, &v_}) a->reserve(pairs.size());
  for (const Correspondence& c : pairs) {
    x_.push_back(c.X_1.x()), y_.push_back(c.X_1.y()), z_.push_back(c.X_1.z());
    u_.push_back(c.uv_2.x()), v_.push_back(c.uv_2.y());
  }
}

void ReprojectionScorer::squaredErrors(const SE3Quat& T_21, std::vector<double>* errors2) const {
  static const bool avx2 = __builtin_cpu_supports("avx2");
  const int n = size();
  errors2->resize(n);
  const Pose pose(T_21);
  const Intrinsics k{fx_, fy_, cx_, cy_};
  if (avx2) {
    scoreAvx2(pose, k, x_.data(), y_.data(), z_.data(), u_.data(), v_.data(), n, errors2->data());
  } else {
    scoreScalar(pose, k, x_.data(), y_.data(), z_.data(), u_.data(), v_.data(), 0, n,
                errors2->data());
  }
}

}  // namespace pnpba
