#include "camera_row.h"

#include <Eigen/Core>

namespace pnpba::bal_detail {
#include "camera_row_impl.h"
}  // namespace pnpba::bal_detail
