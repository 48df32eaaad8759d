// Two agreeing estimates of one relative pose, fused into one: the information-weighted mean in
// the tangent space and the covariance of that mean.
//
// The two-view pose has two estimators that see different evidence of the same motion: the
// feature BA (a few hundred corners, their pixels and depths) and the depth path's RGB-D
// alignment (every pixel's depth and colour). Where both accept a pose and the poses agree
// (path "both"), reporting either one's covariance alone says the pose is less certain than the
// two together make it (covariance_bench, five seeds: the `both` groups' mean NEES read 1.2-3.0
// against 6 that way; 2.9-5.6 fused, docs/two_view.md).
//
// What the estimators share is not counted twice. The calibration's error moves both the same
// way, so its term is carried as a sensitivity (calibrationSensitivity) and combined with the
// fusion's weights, S = W_a S_a + W_b S_b, before its sigmas are applied; the motion term is a
// property of the motion, added once by the caller. The feature pairs, which join the RGB-D
// alignment, are left out of the depth path's estimate the caller fuses (its dense samples'
// own, AlignmentEvidence::dense_step). Only the estimators' own parts, the information scaled by
// the fit, are treated as independent (the depth path's slide term, a floor on how loosely the
// depths alone pin a slide, is not fused: the feature pairs pin it). The depth pixels under
// the feature corners are read by both, a few hundred of the alignment's tens of thousands.
//
// Tangent order [w, v] for the left perturbation T <- exp(d) T, as SE3Quat (DESIGN.md 4).
#pragma once

#include <Eigen/Core>

#include "pnpba/optimize/se3_quat.h"

namespace pnpba {

struct PoseEstimate {
  SE3Quat T_21;
  // The estimator's own covariance, without the calibration and motion terms; `judged` with the
  // variance factors read as at least 1, `nominal` at the nominal noise (TwoViewResult).
  Matrix6d own = Matrix6d::Zero();
  Matrix6d judged = Matrix6d::Zero();
  Matrix6d nominal = Matrix6d::Zero();
  // The pose shift per unit error of fx, fy (relative), cx, cy (px), depth scale (relative).
  Eigen::Matrix<double, 6, 5> calibration_sensitivity = Eigen::Matrix<double, 6, 5>::Zero();
};

// The fused estimate: T = exp(W_b d) T_a with d = log(T_b T_a^-1), W_b = C P_b, C = (P_a +
// P_b)^-1 of the `own` covariances (P their inverses); `judged` and `nominal` fused the same way.
// False (and *fused untouched) when a covariance is not positive definite or the poses are too
// far apart for one tangent space (more than 0.1 rad or 1 m: they do not agree).
bool fusePoseEstimates(const PoseEstimate& a, const PoseEstimate& b, PoseEstimate* fused);

}  // namespace pnpba
