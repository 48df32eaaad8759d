// landmark_elimination.h's kernel for AVX2 + FMA. Built with -mavx2 -mfma and Eigen's namespace
// renamed (optimize/CMakeLists.txt), so that none of this file's Eigen code can stand in for the
// baseline build's identically named functions.
#include "landmark_elimination.h"

#include <Eigen/Core>
#include <Eigen/LU>

namespace pnpba::avx2 {

namespace {
#include "landmark_elimination_impl.h"
}  // namespace

void eliminateLandmarks63(const LandmarkBlocks* landmarks, size_t count,
                          const AdjacentBlock* adjacency, const int* pose_offset,
                          const double* hll, const double* bl, const double* hpl, double lambda,
                          double* dinv, double* S, int lda, double* rhs) {
  eliminateLandmarks63Impl(landmarks, count, adjacency, pose_offset, hll, bl, hpl, lambda, dinv,
                           S, lda, rhs);
}


void backSubstitute63(const LandmarkBlocks* landmarks, size_t count, const AdjacentBlock* adjacency,
                      const int* pose_offset, const double* hpl, const double* dinv,
                      const double* bl, const double* xp, double* xl) {
  backSubstitute63Impl(landmarks, count, adjacency, pose_offset, hpl, dinv, bl, xp, xl);
}

}  // namespace pnpba::avx2
