// landmark_elimination.h's kernels for AVX2 + FMA. Built with -mavx2 -mfma and Eigen's namespace
// renamed (optimize/CMakeLists.txt), so that none of this file's Eigen code can stand in for the
// baseline build's identically named functions.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "landmark_elimination.h"

namespace pnpba::avx2 {
#include "landmark_elimination_impl.h"
}  // namespace pnpba::avx2
