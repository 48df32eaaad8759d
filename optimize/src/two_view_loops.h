// The numeric loops of the two-view kernel (two_view_kernel.h), over structure-of-arrays
// buffers: one lane per point, so that the compiler vectorises across points. Built twice, for
// the baseline instruction set and (two_view_loops_avx2.cpp) for AVX2 with FMA, chosen by
// cpuHasAvx2Fma(); raw arrays in, so that the two builds share no inline code.
//
// Notation (DESIGN.md section 4): a camera maps a point X to P = R X + t and predicts
// (fx Px / Pz + cx, fy Py / Pz + cy); the error is e = z - prediction, A = de/dP, and with the
// information w I an observation gives M = w AᵀA (3 x 3, symmetric) and g = -w Aᵀ e. Symmetric 3 x
// 3 matrices are stored as their six entries 00 01 02 11 12 22.
#pragma once

#include <cstddef>

namespace pnpba::two_view {

// Row-major rotation and translation of one camera.
struct CameraPose {
  double R[9];
  double t[3];
};

// n observations, each of one point by the same camera.
struct ObservationArrays {
  size_t n = 0;
  const double *x = nullptr, *y = nullptr, *z = nullptr;  // the points (world frame)
  const double *mu = nullptr, *mv = nullptr;              // the measured pixels
  const double *fx = nullptr, *fy = nullptr, *cx = nullptr, *cy = nullptr;
  const double* w = nullptr;                           // information scale (Omega = w I)
  double *p0 = nullptr, *p1 = nullptr, *p2 = nullptr;  // P
  double *eu = nullptr, *ev = nullptr;                 // e
  double* m[6] = {};                                   // M, six entries
  double* g[3] = {};
};

// Fills P, e, M and g of every observation; returns the sum of w |e|^2.
double evaluateObservations(const CameraPose& camera, const ObservationArrays& o);

// Rotates M and g of n observations into the world frame: Rᵀ M R (six entries) and Rᵀ g.
void rotateToWorld(const CameraPose& camera, size_t n, double* const m[6], double* const g[3],
                   double* h[6], double* b[3]);

// The two-view RGB-D graph (rgbd_pair.h), one point per lane: camera 1 at the identity and
// camera 2 at (R, t) each observe (u, v, u - bf / z) with a 3 x 3 information (camera 2 without
// depth: its information's third row and column zero), each error's chi2 under a Huber kernel of
// width delta (0: none) whose weight rho' scales its information.
struct StereoPairArrays {
  size_t n = 0;
  double fx = 1, fy = 1, cx = 0, cy = 0, bf = 1;
  double delta1 = 0;                                      // camera 1's width
  const double *x = nullptr, *y = nullptr, *z = nullptr;  // the points
  const double* z1[3] = {};                               // camera 1's measurement
  const double* info1[6] = {};                            // and information (six entries)
  const double* z2[3] = {};
  const double* info2[6] = {};
  const double* delta2 = nullptr;  // camera 2's width per point
  // Written: P, M and g of camera 2's error; F and f, M and g of camera 1's (the world frame);
  // each point's robust chi2 (both errors).
  double* p[3] = {};
  double* m[6] = {};
  double* g[3] = {};
  double* F[6] = {};
  double* f[3] = {};
  double* cost = nullptr;
};

// Fills the arrays; returns the sum of the points' robust chi2.
double evaluateStereoPairs(const CameraPose& camera, const StereoPairArrays& a);

// One point per lane, observed once by the free camera (P, M, g: its observation) and by fixed
// cameras whose terms sum to F (world frame, six entries) and f.
struct PointArrays {
  size_t n = 0;
  const double* p[3] = {};
  const double* m[6] = {};
  const double* g[3] = {};
  const double* F[6] = {};
  const double* f[3] = {};
  // Written by assemble: the point's information and gradient in the free camera's frame,
  // H2 = M + R F Rᵀ and b2 = g + R f.
  double* h2[6] = {};
  double* b2[3] = {};
  double* ninv[6] = {};     // written by eliminate: (H2 + lambda I)^-1
  double* terms = nullptr;  // eliminate's scratch, kEliminationTerms per point
};

// S's lower triangle (21) and rhs (6): what each point adds to them.
constexpr int kEliminationTerms = 27;

// H2 and b2 per point; the world-frame gradient Rᵀ b2 into bl (three per point); the pose's
// gradient sum of [P x g; g] into bp (six).
void assemble(const CameraPose& camera, const PointArrays& a, double* bl, double* bp);

// The largest diagonal entry of the pose's block (sum of Qᵀ M Q, Q = [-[P]x | I]) and of every
// point's world-frame block Rᵀ H2 R: g2o's first damping is tau times it.
double maxDiagonal(const CameraPose& camera, const PointArrays& a);

// The reduced system with the points eliminated at damping lambda: S (6 x 6, column-major; the
// lower triangle written, lambda on its diagonal) and rhs, and ninv per point.
void eliminate(const PointArrays& a, double lambda, double* S, double* rhs);

// The points' steps from the pose's step xp = [omega; upsilon]: xl = Rᵀ ninv (b2 - M (omega x
// P + upsilon)), three per point.
void backSubstitute(const CameraPose& camera, const PointArrays& a, const double* xp, double* xl);

namespace avx2 {
// The same, built for AVX2 + FMA; call only where cpuHasAvx2Fma().
double evaluateObservations(const CameraPose& camera, const ObservationArrays& o);
double evaluateStereoPairs(const CameraPose& camera, const StereoPairArrays& a);
void rotateToWorld(const CameraPose& camera, size_t n, double* const m[6], double* const g[3],
                   double* h[6], double* b[3]);
void assemble(const CameraPose& camera, const PointArrays& a, double* bl, double* bp);
double maxDiagonal(const CameraPose& camera, const PointArrays& a);
void eliminate(const PointArrays& a, double lambda, double* S, double* rhs);
void backSubstitute(const CameraPose& camera, const PointArrays& a, const double* xp, double* xl);
}  // namespace avx2

}  // namespace pnpba::two_view
