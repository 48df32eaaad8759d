// Squared reprojection errors of many 3D-2D pairs under many poses, as a RANSAC scores its
// hypotheses: the pairs' coordinates are laid out once, one array per coordinate, and each pose
// is scored over them four pairs at a time where the CPU has AVX2. Every error has the same bits
// as `(camera.project(T.map(X_1)) - uv_2).squaredNorm()` in Eigen: the same operations in the
// same order, and no fused multiply-add (the library is built without it).
#pragma once

#include <vector>

#include "pnpba/features/correspondences.h"
#include "pnpba/features/pinhole_camera.h"
#include "pnpba/optimize/se3_quat.h"

namespace pnpba {

class ReprojectionScorer {
 public:
  ReprojectionScorer(const Correspondences& pairs, const PinholeCamera& camera);

  int size() const { return static_cast<int>(x_.size()); }
  // errors2[i] = squared pixel error of pair i under T_21 (infinity where the point is not in
  // front of camera 2). `errors2` is resized to size().
  void squaredErrors(const SE3Quat& T_21, std::vector<double>* errors2) const;

 private:
  std::vector<double> x_, y_, z_, u_, v_;  // X_1 and uv_2
  double fx_, fy_, cx_, cy_;
};

}  // namespace pnpba
