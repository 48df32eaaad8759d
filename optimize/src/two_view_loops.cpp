// two_view_loops.h's loops for the baseline instruction set.
#include "two_view_loops.h"

#include <cmath>
#include <initializer_list>

namespace pnpba::two_view {
#include "two_view_loops_impl.h"
}  // namespace pnpba::two_view
