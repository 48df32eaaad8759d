// two_view_loops.h's loops for AVX2 + FMA (optimize/CMakeLists.txt), four points per vector.
#include <cmath>
#include <initializer_list>

#include "two_view_loops.h"

namespace pnpba::two_view::avx2 {
#include "two_view_loops_impl.h"
}  // namespace pnpba::two_view::avx2
