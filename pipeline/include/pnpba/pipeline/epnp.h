// EPnP (Lepetit, Moreno-Noguer and Fua, IJCV 2009): the pose of camera 2 from n >= 4 points of
// camera 1 and their undistorted pixels in image 2, in closed form. The same estimator as
// cv::solvePnP(SOLVEPNP_EPNP) (four control points, the null space of the 2n x 12 system, betas
// for one, two and three null vectors refined by five Gauss-Newton steps, the lowest mean
// reprojection error kept), written on fixed-size Eigen matrices: OpenCV's takes about 330 k
// instructions per five-point sample, 60 % of them a Jacobi SVD of the 12 x 12 normal matrix,
// which RANSAC pays on every sample (pnp_ransac.cpp).
#pragma once

#include "pnpba/features/correspondences.h"
#include "pnpba/optimize/se3_quat.h"

namespace pnpba {

// T_21 from the pairs listed in `subset` (count >= 4 indices into `pairs`). False, with *T_21
// untouched, when the points are degenerate (collinear, coincident) or the result is not finite.
bool solveEpnp(const Correspondences& pairs, const int* subset, int count,
               const PinholeCamera& camera, SE3Quat* T_21);

}  // namespace pnpba
