#include "dense_cholesky.h"

#include <Eigen/Cholesky>
#include <algorithm>

namespace pnpba::bal_detail {
#include "dense_cholesky_impl.h"
}  // namespace pnpba::bal_detail
