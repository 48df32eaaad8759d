#include "camera_row.h"

#include <Eigen/Core>

namespace pnpba::bal_detail {

namespace {
#include "camera_row_impl.h"
}  // namespace

void buildCameraRow(const CameraRowData& data, int a, const int* slot, int blocks, double* rows,
                    double* rhs) {
  buildCameraRowImpl(data, a, slot, blocks, rows, rhs);
}

}  // namespace pnpba::bal_detail
