// A camera pose as the two-view loops take it (two_view_loops.h): the rotation row-major and the
// translation, from an SE3Quat (internal; the kernel, the RGB-D pair solver and their tests).
#pragma once

#include "pnpba/optimize/se3_quat.h"
#include "two_view_loops.h"

namespace pnpba {

inline two_view::CameraPose cameraPoseOf(const SE3Quat& T) {
  two_view::CameraPose c;
  const Eigen::Matrix3d R = T.rotation().toRotationMatrix();
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) c.R[3 * r + k] = R(r, k);
    c.t[r] = T.translation()[r];
  }
  return c;
}

}  // namespace pnpba
