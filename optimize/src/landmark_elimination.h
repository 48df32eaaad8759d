// The native LM's elimination of landmarks (points) from the damped normal equations, for the
// common graph of 6-dof poses and 3-dof points: S -= H_pl D H_plᵀ and rhs -= H_pl D b_l per
// point, D = (H_ll + lambda I)^-1 kept for the back-substitution (native_levenberg.h). Built
// twice, for the baseline instruction set and (landmark_elimination_avx2.cpp) for AVX2 with FMA,
// chosen by cpuHasAvx2Fma() (pnpba/core/cpu_features.h): the 6 x 3 and 6 x 6 products are a
// fifth of a small graph's solve. Raw arrays in, so that the two builds of Eigen never meet.
#pragma once

#include <cstddef>

namespace pnpba {

// A landmark's blocks: offsets into the 3 x 3 H_ll (and D) array and the 3-vector b_l array, and
// its range of pose-landmark blocks.
struct LandmarkBlocks {
  int dim = 0;
  size_t hll = 0;                     // offset into hll and dinv (dim x dim)
  size_t bl = 0;                      // offset into bl and xl
  size_t adj_begin = 0, adj_end = 0;  // range in the adjacency
};
// One pose-landmark block: the pose's index and the offset of the (pose_dim x dim) H_pl block.
struct AdjacentBlock {
  int pose = 0;
  size_t hpl = 0;
};

// The 6/3 case: S (n x n column-major, leading dimension lda) and rhs at pose_offset[pose]; only
// the blocks on and below S's block diagonal are written (the Cholesky reads nothing else).
void eliminateLandmarks63(const LandmarkBlocks* landmarks, size_t count,
                          const AdjacentBlock* adjacency, const int* pose_offset, const double* hll,
                          const double* bl, const double* hpl, double lambda, double* dinv,
                          double* S, int lda, double* rhs);

// The points' steps from the poses' step xp: xl = D (b_l - H_plᵀ xp) per point.
void backSubstitute63(const LandmarkBlocks* landmarks, size_t count, const AdjacentBlock* adjacency,
                      const int* pose_offset, const double* hpl, const double* dinv,
                      const double* bl, const double* xp, double* xl);

namespace avx2 {
// The same, built for AVX2 + FMA; call only where cpuHasAvx2Fma().
void backSubstitute63(const LandmarkBlocks* landmarks, size_t count, const AdjacentBlock* adjacency,
                      const int* pose_offset, const double* hpl, const double* dinv,
                      const double* bl, const double* xp, double* xl);
void eliminateLandmarks63(const LandmarkBlocks* landmarks, size_t count,
                          const AdjacentBlock* adjacency, const int* pose_offset, const double* hll,
                          const double* bl, const double* hpl, double lambda, double* dinv,
                          double* S, int lda, double* rhs);
}  // namespace avx2

}  // namespace pnpba
