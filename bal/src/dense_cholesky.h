// The dense reduced camera system's solve: S x = b by Cholesky, in place, for a symmetric
// positive definite S of which only the upper triangle is read (column-major, n x n), the
// factorisation's panels and updates shared over `threads`.
//
// The blocked Cholesky is built twice: for the baseline instruction set and, in
// dense_cholesky_avx2.cpp, for AVX2 with FMA, which the solve uses where the CPU has both. The
// factorisation is most of a dense solve's linear algebra, and 4-wide fused multiply-adds halve
// it (Ladybug-49's 441 x 441: 1.9 -> 0.9 ms a factorisation). The interface is raw arrays so
// that the two builds of Eigen never meet: the AVX2 one lives in its own namespace.
#pragma once

namespace pnpba::bal_detail {

// Factors `upper` in place and overwrites `rhs` with the solution; false when S is not
// positive definite. The lower triangle is left with the updates' scratch values. The result
// does not depend on `threads`.
bool solveDenseSpd(double* upper, int n, double* rhs, int threads);
bool solveDenseSpd(float* upper, int n, float* rhs, int threads);

namespace avx2 {
// The same, built for AVX2 + FMA; call only where cpuHasAvx2Fma() (pnpba/core/cpu_features.h).
bool solveDenseSpd(double* upper, int n, double* rhs, int threads);
bool solveDenseSpd(float* upper, int n, float* rhs, int threads);
}  // namespace avx2

}  // namespace pnpba::bal_detail
