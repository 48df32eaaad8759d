#include "pnpba/pipeline/pose_fusion.h"

#include <Eigen/Cholesky>

namespace pnpba {

namespace {

// The inverse of a symmetric positive definite covariance; false when it is not one.
bool informationOf(const Matrix6d& covariance, Matrix6d* information) {
  const Eigen::LLT<Matrix6d> llt(0.5 * (covariance + covariance.transpose()));
  if (llt.info() != Eigen::Success) return false;
  *information = llt.solve(Matrix6d::Identity());
  return information->allFinite();
}

// (A^-1 + B^-1)^-1 for positive definite A and B; false when either is not.
bool fusedCovariance(const Matrix6d& a, const Matrix6d& b, Matrix6d* fused) {
  Matrix6d pa, pb;
  if (!informationOf(a, &pa) || !informationOf(b, &pb)) return false;
  Matrix6d c;
  if (!informationOf(pa + pb, &c)) return false;
  *fused = 0.5 * (c + c.transpose());
  return true;
}

}  // namespace

bool fusePoseEstimates(const PoseEstimate& a, const PoseEstimate& b, PoseEstimate* fused) {
  Matrix6d pa, pb, c, judged, nominal;
  if (!informationOf(a.own, &pa) || !informationOf(b.own, &pb) || !informationOf(pa + pb, &c) ||
      !fusedCovariance(a.judged, b.judged, &judged) ||
      !fusedCovariance(a.nominal, b.nominal, &nominal)) {
    return false;
  }
  const Vector6d d = (b.T_21 * a.T_21.inverse()).log();
  constexpr double kMaxAngle = 0.1, kMaxDistance = 1.0;  // far beyond two poses that agree
  if (!d.allFinite() || d.head<3>().norm() > kMaxAngle || d.tail<3>().norm() > kMaxDistance) {
    return false;
  }
  const Matrix6d w_a = c * pa, w_b = c * pb;
  fused->T_21 = SE3Quat::exp(w_b * d) * a.T_21;
  fused->own = 0.5 * (c + c.transpose());
  fused->judged = judged;
  fused->nominal = nominal;
  fused->calibration_sensitivity =
      w_a * a.calibration_sensitivity + w_b * b.calibration_sensitivity;
  return true;
}

}  // namespace pnpba
