// dense_cholesky.h's solves for AVX2 + FMA. Built with -mavx2 -mfma and Eigen's namespace
// renamed (bal/CMakeLists.txt), so that none of this file's Eigen code can be picked by the
// linker for the baseline build's identical-looking symbols.
#include <Eigen/Cholesky>
#include <algorithm>

#include "dense_cholesky.h"

namespace pnpba::bal_detail::avx2 {
#include "dense_cholesky_impl.h"
}  // namespace pnpba::bal_detail::avx2
