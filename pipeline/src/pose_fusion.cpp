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

// Two covariances A and B combined as independent: their informations and (A^-1 + B^-1)^-1.
struct Combined {
  Matrix6d information_a, information_b, covariance;
};

// False when A, B or their summed information is not positive definite.
bool combine(const Matrix6d& a, const Matrix6d& b, Combined* out) {
  Matrix6d c;
  if (!informationOf(a, &out->information_a) || !informationOf(b, &out->information_b) ||
      !informationOf(out->information_a + out->information_b, &c)) {
    return false;
  }
  out->covariance = 0.5 * (c + c.transpose());
  return true;
}

}  // namespace

bool fusePoseEstimates(const PoseEstimate& a, const PoseEstimate& b, PoseEstimate* fused) {
  Combined own, judged, nominal;
  if (!combine(a.own, b.own, &own) || !combine(a.judged, b.judged, &judged) ||
      !combine(a.nominal, b.nominal, &nominal)) {
    return false;
  }
  const Vector6d d = (b.T_21 * a.T_21.inverse()).log();
  constexpr double kMaxAngle = 0.1, kMaxDistance = 1.0;  // far beyond two poses that agree
  if (!d.allFinite() || d.head<3>().norm() > kMaxAngle || d.tail<3>().norm() > kMaxDistance) {
    return false;
  }
  const Matrix6d w_a = own.covariance * own.information_a;
  const Matrix6d w_b = own.covariance * own.information_b;
  fused->T_21 = SE3Quat::exp(w_b * d) * a.T_21;
  fused->own = own.covariance;
  fused->judged = judged.covariance;
  fused->nominal = nominal.covariance;
  fused->calibration_sensitivity =
      w_a * a.calibration_sensitivity + w_b * b.calibration_sensitivity;
  return true;
}

}  // namespace pnpba
