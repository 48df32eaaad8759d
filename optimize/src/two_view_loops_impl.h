// The definitions of two_view_loops.h's loops, included by two_view_loops.cpp (in
// pnpba::two_view) and two_view_loops_avx2.cpp (in pnpba::two_view::avx2). No include guard:
// each file includes it once. Every loop runs one point (or observation) per lane; sums over
// points are OpenMP SIMD reductions (-fopenmp-simd: no threads, no runtime), so their order of
// addition is the vector width's, not the points'. GCC 12 vectorises a reduction only in a loop
// that stores nothing, and an array only where the loop keeps it in registers: the sums have
// loops of their own, and the small matrices are named scalars.

namespace {

// Small matrices as named scalars, not arrays: inside a loop vectorised across points an array
// would live in memory, one copy per lane; scalars stay in registers.
struct V3 {
  double x, y, z;
};
struct M3 {  // row-major
  double xx, xy, xz, yx, yy, yz, zx, zy, zz;
};
struct S3 {  // symmetric
  double xx, xy, xz, yy, yz, zz;
};

inline M3 rowMajor(const double* R) {
  return {R[0], R[1], R[2], R[3], R[4], R[5], R[6], R[7], R[8]};
}
inline S3 load(const double* const a[6], size_t i) {
  return {a[0][i], a[1][i], a[2][i], a[3][i], a[4][i], a[5][i]};
}
inline void store(const S3& s, double* const a[6], size_t i) {
  a[0][i] = s.xx, a[1][i] = s.xy, a[2][i] = s.xz, a[3][i] = s.yy, a[4][i] = s.yz, a[5][i] = s.zz;
}
inline V3 load3(const double* const a[3], size_t i) { return {a[0][i], a[1][i], a[2][i]}; }

inline V3 mul(const S3& A, const V3& v) {
  return {A.xx * v.x + A.xy * v.y + A.xz * v.z, A.xy * v.x + A.yy * v.y + A.yz * v.z,
          A.xz * v.x + A.yz * v.y + A.zz * v.z};
}
inline V3 mul(const M3& R, const V3& v) {
  return {R.xx * v.x + R.xy * v.y + R.xz * v.z, R.yx * v.x + R.yy * v.y + R.yz * v.z,
          R.zx * v.x + R.zy * v.y + R.zz * v.z};
}
inline V3 mulT(const M3& R, const V3& v) {  // Rᵀ v
  return {R.xx * v.x + R.yx * v.y + R.zx * v.z, R.xy * v.x + R.yy * v.y + R.zy * v.z,
          R.xz * v.x + R.yz * v.y + R.zz * v.z};
}
inline V3 cross(const V3& a, const V3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
// A B for symmetric A and B (a general matrix).
inline M3 mul(const S3& A, const S3& B) {
  return {A.xx * B.xx + A.xy * B.xy + A.xz * B.xz, A.xx * B.xy + A.xy * B.yy + A.xz * B.yz,
          A.xx * B.xz + A.xy * B.yz + A.xz * B.zz, A.xy * B.xx + A.yy * B.xy + A.yz * B.xz,
          A.xy * B.xy + A.yy * B.yy + A.yz * B.yz, A.xy * B.xz + A.yy * B.yz + A.yz * B.zz,
          A.xz * B.xx + A.yz * B.xy + A.zz * B.xz, A.xz * B.xy + A.yz * B.yy + A.zz * B.yz,
          A.xz * B.xz + A.yz * B.yz + A.zz * B.zz};
}
// C B for a general C and symmetric B, where C B is known to be symmetric.
inline S3 mulSymmetric(const M3& C, const S3& B) {
  return {C.xx * B.xx + C.xy * B.xy + C.xz * B.xz, C.xx * B.xy + C.xy * B.yy + C.xz * B.yz,
          C.xx * B.xz + C.xy * B.yz + C.xz * B.zz, C.yx * B.xy + C.yy * B.yy + C.yz * B.yz,
          C.yx * B.xz + C.yy * B.yz + C.yz * B.zz, C.zx * B.xz + C.zy * B.yz + C.zz * B.zz};
}
// R A Rᵀ and Rᵀ A R for symmetric A.
inline S3 rotate(const M3& R, const S3& A) {
  const V3 r0{R.xx, R.xy, R.xz}, r1{R.yx, R.yy, R.yz}, r2{R.zx, R.zy, R.zz};
  const V3 a0 = mul(A, r0), a1 = mul(A, r1), a2 = mul(A, r2);
  auto dot = [](const V3& a, const V3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; };
  return {dot(r0, a0), dot(r0, a1), dot(r0, a2), dot(r1, a1), dot(r1, a2), dot(r2, a2)};
}
inline S3 rotateT(const M3& R, const S3& A) {
  return rotate({R.xx, R.yx, R.zx, R.xy, R.yy, R.zy, R.xz, R.yz, R.zz}, A);
}
// The inverse of a symmetric positive definite matrix by its adjugate.
inline S3 inverse(const S3& N) {
  const double c00 = N.yy * N.zz - N.yz * N.yz, c01 = N.xz * N.yz - N.xy * N.zz;
  const double c02 = N.xy * N.yz - N.xz * N.yy, c11 = N.xx * N.zz - N.xz * N.xz;
  const double c12 = N.xy * N.xz - N.xx * N.yz, c22 = N.xx * N.yy - N.xy * N.xy;
  const double inv_det = 1.0 / (N.xx * c00 + N.xy * c01 + N.xz * c02);
  return {c00 * inv_det, c01 * inv_det, c02 * inv_det, c11 * inv_det, c12 * inv_det, c22 * inv_det};
}

}  // namespace

double evaluateObservations(const CameraPose& camera, const ObservationArrays& o) {
  const double *R = camera.R, *t = camera.t;
#pragma omp simd
  for (size_t i = 0; i < o.n; ++i) {
    const double X = o.x[i], Y = o.y[i], Z = o.z[i];
    const double P0 = R[0] * X + R[1] * Y + R[2] * Z + t[0];
    const double P1 = R[3] * X + R[4] * Y + R[5] * Z + t[1];
    const double P2 = R[6] * X + R[7] * Y + R[8] * Z + t[2];
    const double iz = 1.0 / P2;
    const double fx = o.fx[i], fy = o.fy[i], w = o.w[i];
    const double eu = o.mu[i] - (fx * P0 * iz + o.cx[i]);
    const double ev = o.mv[i] - (fy * P1 * iz + o.cy[i]);
    // A = [-fx iz, 0, fx P0 iz^2; 0, -fy iz, fy P1 iz^2]
    const double a0 = -fx * iz, a2 = fx * P0 * iz * iz;
    const double b1 = -fy * iz, b2 = fy * P1 * iz * iz;
    o.p0[i] = P0, o.p1[i] = P1, o.p2[i] = P2;
    o.eu[i] = eu, o.ev[i] = ev;
    o.m[0][i] = w * a0 * a0;
    o.m[1][i] = 0.0;  // a pinhole's A has a zero in each row where the other has not
    o.m[2][i] = w * a0 * a2;
    o.m[3][i] = w * b1 * b1;
    o.m[4][i] = w * b1 * b2;
    o.m[5][i] = w * (a2 * a2 + b2 * b2);
    o.g[0][i] = -w * a0 * eu;
    o.g[1][i] = -w * b1 * ev;
    o.g[2][i] = -w * (a2 * eu + b2 * ev);
  }
  // The sum on its own: GCC 12 leaves a loop with both stores and a reduction scalar.
  double chi2 = 0;
#pragma omp simd reduction(+ : chi2)
  for (size_t i = 0; i < o.n; ++i) chi2 += o.w[i] * (o.eu[i] * o.eu[i] + o.ev[i] * o.ev[i]);
  return chi2;
}

namespace {

// Huber's rho and rho' of a chi2 (huber.h's, branch-free for the vector lanes).
inline void huber(double chi2, double delta, double* cost, double* weight) {
  const double root = std::sqrt(chi2);
  const bool inside = !(delta > 0) || chi2 <= delta * delta;
  *cost = inside ? chi2 : 2.0 * delta * root - delta * delta;
  *weight = inside ? 1.0 : delta / root;
}

// A stereo error's terms at P: e = z - (fx Px/Pz + cx, fy Py/Pz + cy, u - bf/Pz), A = de/dP,
// W = rho' Omega; M = Aᵀ W A, g = -Aᵀ W e; returns the robust chi2.
inline double stereoTerms(const V3& P, const V3& z, const S3& info, double delta, double fx,
                          double fy, double cx, double cy, double bf, S3* M, V3* g) {
  const double iz = 1.0 / P.z;
  const double u = fx * P.x * iz + cx;
  const V3 e{z.x - u, z.y - (fy * P.y * iz + cy), z.z - (u - bf * iz)};
  const V3 We = mul(info, e);
  const double chi2 = e.x * We.x + e.y * We.y + e.z * We.z;
  double cost, w;
  huber(chi2, delta, &cost, &w);
  // Rows of A: (-fx iz, 0, fx Px iz^2), (0, -fy iz, fy Py iz^2), (-fx iz, 0, (fx Px - bf) iz^2).
  const double a = -fx * iz, b = -fy * iz;
  const double c0 = fx * P.x * iz * iz, c1 = fy * P.y * iz * iz, c2 = (fx * P.x - bf) * iz * iz;
  // W A's columns: W (a, 0, a), W (0, b, 0), W (c0, c1, c2).
  const S3 W{w * info.xx, w * info.xy, w * info.xz, w * info.yy, w * info.yz, w * info.zz};
  const V3 k0 = mul(W, V3{a, 0.0, a}), k1 = mul(W, V3{0.0, b, 0.0});
  const V3 k2 = mul(W, V3{c0, c1, c2});
  // M = Aᵀ (W A): entry (r, c) is column r of A through W's column c.
  *M = {a * (k0.x + k0.z), a * (k1.x + k1.z), a * (k2.x + k2.z),
        b * k1.y,          b * k2.y,          c0 * k2.x + c1 * k2.y + c2 * k2.z};
  const V3 Wwe{w * We.x, w * We.y, w * We.z};
  *g = {-a * (Wwe.x + Wwe.z), -b * Wwe.y, -(c0 * Wwe.x + c1 * Wwe.y + c2 * Wwe.z)};
  return cost;
}

}  // namespace

double evaluateStereoPairs(const CameraPose& camera, const StereoPairArrays& a) {
  const M3 R = rowMajor(camera.R);
  const V3 t{camera.t[0], camera.t[1], camera.t[2]};
#pragma omp simd
  for (size_t i = 0; i < a.n; ++i) {
    const V3 X{a.x[i], a.y[i], a.z[i]};
    const V3 RX = mul(R, X);
    const V3 P{RX.x + t.x, RX.y + t.y, RX.z + t.z};
    S3 M, F;
    V3 g, f;
    const double cost2 = stereoTerms(P, load3(a.z2, i), load(a.info2, i), a.delta2[i], a.fx, a.fy,
                                     a.cx, a.cy, a.bf, &M, &g);
    const double cost1 = stereoTerms(X, load3(a.z1, i), load(a.info1, i), a.delta1, a.fx, a.fy,
                                     a.cx, a.cy, a.bf, &F, &f);
    a.p[0][i] = P.x, a.p[1][i] = P.y, a.p[2][i] = P.z;
    store(M, a.m, i);
    a.g[0][i] = g.x, a.g[1][i] = g.y, a.g[2][i] = g.z;
    store(F, a.F, i);
    a.f[0][i] = f.x, a.f[1][i] = f.y, a.f[2][i] = f.z;
    a.cost[i] = cost2 + cost1;
  }
  double total = 0;
#pragma omp simd reduction(+ : total)
  for (size_t i = 0; i < a.n; ++i) total += a.cost[i];
  return total;
}

void rotateToWorld(const CameraPose& camera, size_t n, double* const m[6], double* const g[3],
                   double* h[6], double* b[3]) {
  const M3 R = rowMajor(camera.R);
#pragma omp simd
  for (size_t i = 0; i < n; ++i) {
    store(rotateT(R, load(m, i)), h, i);
    const V3 bw = mulT(R, load3(g, i));
    b[0][i] = bw.x, b[1][i] = bw.y, b[2][i] = bw.z;
  }
}

void assemble(const CameraPose& camera, const PointArrays& a, double* bl, double* bp) {
  const M3 R = rowMajor(camera.R);
#pragma omp simd
  for (size_t i = 0; i < a.n; ++i) {
    const S3 M = load(a.m, i), RF = rotate(R, load(a.F, i));
    store({M.xx + RF.xx, M.xy + RF.xy, M.xz + RF.xz, M.yy + RF.yy, M.yz + RF.yz, M.zz + RF.zz},
          a.h2, i);
    const V3 g = load3(a.g, i), Rf = mul(R, load3(a.f, i));
    const V3 b2{g.x + Rf.x, g.y + Rf.y, g.z + Rf.z};
    a.b2[0][i] = b2.x, a.b2[1][i] = b2.y, a.b2[2][i] = b2.z;
    const V3 world = mulT(R, b2);
    bl[3 * i] = world.x, bl[3 * i + 1] = world.y, bl[3 * i + 2] = world.z;
  }
  double s0 = 0, s1 = 0, s2 = 0, s3 = 0, s4 = 0, s5 = 0;
#pragma omp simd reduction(+ : s0, s1, s2, s3, s4, s5)
  for (size_t i = 0; i < a.n; ++i) {
    const V3 g = load3(a.g, i), Pg = cross(load3(a.p, i), g);
    s0 += Pg.x, s1 += Pg.y, s2 += Pg.z;
    s3 += g.x, s4 += g.y, s5 += g.z;
  }
  bp[0] = s0, bp[1] = s1, bp[2] = s2, bp[3] = s3, bp[4] = s4, bp[5] = s5;
}

// Px A Pxᵀ for symmetric A, Px = [P]x the cross-product matrix: the rotation block of Qᵀ A Q.
inline S3 crossSandwich(const V3& P, const S3& A) {
  // Rows of Px: (0, -z, y), (z, 0, -x), (-y, x, 0).
  const V3 r0{0.0, -P.z, P.y}, r1{P.z, 0.0, -P.x}, r2{-P.y, P.x, 0.0};
  const V3 a0 = mul(A, r0), a1 = mul(A, r1), a2 = mul(A, r2);
  auto dot = [](const V3& a, const V3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; };
  return {dot(r0, a0), dot(r1, a0), dot(r2, a0), dot(r1, a1), dot(r2, a1), dot(r2, a2)};
}

double maxDiagonal(const CameraPose& camera, const PointArrays& a) {
  const M3 R = rowMajor(camera.R);
  double d0 = 0, d1 = 0, d2 = 0, d3 = 0, d4 = 0, d5 = 0, points = 0;
#pragma omp simd reduction(+ : d0, d1, d2, d3, d4, d5) reduction(max : points)
  for (size_t i = 0; i < a.n; ++i) {
    const S3 M = load(a.m, i);
    const S3 top = crossSandwich(load3(a.p, i), M);
    d0 += top.xx, d1 += top.yy, d2 += top.zz;
    d3 += M.xx, d4 += M.yy, d5 += M.zz;
    const S3 H = rotateT(R, load(a.h2, i));
    const double most = H.xx > H.yy ? (H.xx > H.zz ? H.xx : H.zz) : (H.yy > H.zz ? H.yy : H.zz);
    points = points > most ? points : most;
  }
  double best = points;
  for (double d : {d0, d1, d2, d3, d4, d5}) best = best > d ? best : d;
  return best;
}

void eliminate(const PointArrays& a, double lambda, double* S, double* rhs) {
  // Per point, its 27 terms of S's lower triangle and of rhs (lane-major in a.terms); then their
  // sums, a few at a time: GCC vectorises a loop with a handful of reductions, not 27.
  const size_t n = a.n;
  double* t[kEliminationTerms];
  for (int k = 0; k < kEliminationTerms; ++k) t[k] = a.terms + k * n;
#pragma omp simd
  for (size_t i = 0; i < n; ++i) {
    const S3 H2 = load(a.h2, i);
    const S3 Ninv = inverse({H2.xx + lambda, H2.xy, H2.xz, H2.yy + lambda, H2.yz, H2.zz + lambda});
    store(Ninv, a.ninv, i);
    const S3 M = load(a.m, i);
    const M3 MN = mul(M, Ninv);
    // K = M - M Ninv M (what the point leaves of the pose's information, camera frame) and
    // k = g - M Ninv b2 (of its gradient).
    const S3 MNM = mulSymmetric(MN, M);
    const S3 K{M.xx - MNM.xx, M.xy - MNM.xy, M.xz - MNM.xz,
               M.yy - MNM.yy, M.yz - MNM.yz, M.zz - MNM.zz};
    const V3 g = load3(a.g, i), MNb = mul(MN, load3(a.b2, i));
    const V3 k{g.x - MNb.x, g.y - MNb.y, g.z - MNb.z};
    // Qᵀ K Q with Q = [-[P]x | I]: [[Px K Pxᵀ, Px K], [(Px K)ᵀ, K]]; Qᵀ k = [P x k; k].
    const V3 P = load3(a.p, i);
    const S3 top = crossSandwich(P, K);
    // Column c of Px K is P x (column c of K): S's entries (3 + c, 0..2).
    const V3 c0 = cross(P, {K.xx, K.xy, K.xz}), c1 = cross(P, {K.xy, K.yy, K.yz});
    const V3 c2 = cross(P, {K.xz, K.yz, K.zz});
    const V3 Pk = cross(P, k);
    // S 00 10 11 20 21 22
    t[0][i] = top.xx, t[1][i] = top.xy, t[2][i] = top.yy, t[3][i] = top.xz, t[4][i] = top.yz,
    t[5][i] = top.zz;
    // S 30 31 32 40 41 42
    t[6][i] = c0.x, t[7][i] = c0.y, t[8][i] = c0.z, t[9][i] = c1.x, t[10][i] = c1.y,
    t[11][i] = c1.z;
    // S 50 51 52
    t[12][i] = c2.x, t[13][i] = c2.y, t[14][i] = c2.z;
    // S 33 43 44 53 54 55
    t[15][i] = K.xx, t[16][i] = K.xy, t[17][i] = K.yy, t[18][i] = K.xz, t[19][i] = K.yz,
    t[20][i] = K.zz;
    // rhs
    t[21][i] = Pk.x, t[22][i] = Pk.y, t[23][i] = Pk.z, t[24][i] = k.x, t[25][i] = k.y,
    t[26][i] = k.z;
  }
  double sum[kEliminationTerms];
  for (int k = 0; k < kEliminationTerms; k += 3) {
    const double *x0 = t[k], *x1 = t[k + 1], *x2 = t[k + 2];
    double s0 = 0, s1 = 0, s2 = 0;
#pragma omp simd reduction(+ : s0, s1, s2)
    for (size_t i = 0; i < n; ++i) s0 += x0[i], s1 += x1[i], s2 += x2[i];
    sum[k] = s0, sum[k + 1] = s1, sum[k + 2] = s2;
  }
  auto at = [S](int row, int col) -> double& { return S[row + 6 * col]; };
  at(0, 0) = sum[0] + lambda, at(1, 0) = sum[1], at(1, 1) = sum[2] + lambda;
  at(2, 0) = sum[3], at(2, 1) = sum[4], at(2, 2) = sum[5] + lambda;
  at(3, 0) = sum[6], at(3, 1) = sum[7], at(3, 2) = sum[8];
  at(4, 0) = sum[9], at(4, 1) = sum[10], at(4, 2) = sum[11];
  at(5, 0) = sum[12], at(5, 1) = sum[13], at(5, 2) = sum[14];
  at(3, 3) = sum[15] + lambda, at(4, 3) = sum[16], at(4, 4) = sum[17] + lambda;
  at(5, 3) = sum[18], at(5, 4) = sum[19], at(5, 5) = sum[20] + lambda;
  for (int r = 0; r < 6; ++r) rhs[r] = sum[21 + r];
}

void backSubstitute(const CameraPose& camera, const PointArrays& a, const double* xp, double* xl) {
  const M3 R = rowMajor(camera.R);
  const V3 omega{xp[0], xp[1], xp[2]}, upsilon{xp[3], xp[4], xp[5]};
#pragma omp simd
  for (size_t i = 0; i < a.n; ++i) {
    // The point's motion under the pose's step, omega x P + upsilon.
    const V3 wP = cross(omega, load3(a.p, i));
    const V3 Mu = mul(load(a.m, i), V3{wP.x + upsilon.x, wP.y + upsilon.y, wP.z + upsilon.z});
    const V3 b2 = load3(a.b2, i);
    const V3 y = mul(load(a.ninv, i), V3{b2.x - Mu.x, b2.y - Mu.y, b2.z - Mu.z});
    const V3 world = mulT(R, y);
    xl[3 * i] = world.x, xl[3 * i + 1] = world.y, xl[3 * i + 2] = world.z;
  }
}
