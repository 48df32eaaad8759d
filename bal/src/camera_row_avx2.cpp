// camera_row.h's kernel for AVX2 + FMA. Built with -mavx2 -mfma and Eigen's namespace renamed
// (bal/CMakeLists.txt), as dense_cholesky_avx2.cpp.
#include <Eigen/Core>

#include "camera_row.h"

namespace pnpba::bal_detail::avx2 {
#include "camera_row_impl.h"
}  // namespace pnpba::bal_detail::avx2
