// The BAL (Snavely) camera on its raw 9 parameters, exactly as Ceres's bundle_adjuster example
// models it, with analytic fixed-size Jacobians for the dedicated solver:
//   P = R(w) X + t,  p = -P.xy / P.z,  d = 1 + k1 |p|^2 + k2 |p|^4,  r = f d p - (u, v)
// The camera is [w (angle-axis), t, f, k1, k2], updated additively (no manifold), so the
// solver's steps and stopping tests are Ceres's.
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace pnpba::bal_detail {

using Matrix29 = Eigen::Matrix<double, 2, 9>;
using Matrix23 = Eigen::Matrix<double, 2, 3>;

inline Eigen::Matrix3d hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// R(w) and the left Jacobian J_l(w) of SO(3): R(w + e) ~ exp(J_l e) R(w).
inline void rotationAndLeftJacobian(const Eigen::Vector3d& w, Eigen::Matrix3d* R,
                                    Eigen::Matrix3d* Jl) {
  const double theta2 = w.squaredNorm();
  if (theta2 > 1e-20) {
    const double theta = std::sqrt(theta2), s = std::sin(theta), c = std::cos(theta);
    const Eigen::Vector3d a = w / theta;
    const Eigen::Matrix3d A = hat(a), aa = a * a.transpose();
    *R = c * Eigen::Matrix3d::Identity() + (1 - c) * aa + s * A;
    if (Jl) {
      *Jl =
          (s / theta) * Eigen::Matrix3d::Identity() + (1 - s / theta) * aa + ((1 - c) / theta) * A;
    }
  } else {  // first order, as Ceres's AngleAxisRotatePoint near zero
    *R = Eigen::Matrix3d::Identity() + hat(w);
    if (Jl) *Jl = Eigen::Matrix3d::Identity() + 0.5 * hat(w);
  }
}

// A camera's rotation and left Jacobian, computed once per camera and shared by all its
// observations (the trigonometry is the costly part of an observation).
struct CameraRotation {
  Eigen::Matrix3d R, Jl;
};

inline CameraRotation cameraRotation(const double* camera) {
  CameraRotation c;
  rotationAndLeftJacobian(Eigen::Map<const Eigen::Vector3d>(camera), &c.R, &c.Jl);
  return c;
}

// Residual (predicted - observed) of one observation; the Jacobians when asked.
inline Eigen::Vector2d snavelyResidual(const double* camera, const CameraRotation& rotation,
                                       const double* point, double u, double v,
                                       Matrix29* J_camera = nullptr, Matrix23* J_point = nullptr) {
  const Eigen::Map<const Eigen::Vector3d> t(camera + 3), X(point);
  const double f = camera[6], k1 = camera[7], k2 = camera[8];
  const Eigen::Matrix3d& R = rotation.R;
  const Eigen::Vector3d RX = R * X;
  const Eigen::Vector3d P = RX + t;
  const Eigen::Vector2d p(-P.x() / P.z(), -P.y() / P.z());
  const double r2 = p.squaredNorm();
  const double d = 1 + r2 * (k1 + k2 * r2);
  const Eigen::Vector2d residual(f * d * p.x() - u, f * d * p.y() - v);
  if (J_camera || J_point) {
    // d(prediction)/dp, then d p / d P.
    const Eigen::Matrix2d dpred_dp =
        f * (d * Eigen::Matrix2d::Identity() + 2 * (k1 + 2 * k2 * r2) * p * p.transpose());
    const double iz = 1 / P.z();
    Matrix23 dp_dP;
    dp_dP << -iz, 0, P.x() * iz * iz, 0, -iz, P.y() * iz * iz;
    const Matrix23 A = dpred_dp * dp_dP;
    if (J_camera) {
      J_camera->leftCols<3>() = -A * hat(RX) * rotation.Jl;
      J_camera->middleCols<3>(3) = A;
      J_camera->col(6) = d * p;
      J_camera->col(7) = f * r2 * p;
      J_camera->col(8) = f * r2 * r2 * p;
    }
    if (J_point) *J_point = A * R;
  }
  return residual;
}

// The same for a single observation, the rotation computed here.
inline Eigen::Vector2d snavelyResidual(const double* camera, const double* point, double u,
                                       double v, Matrix29* J_camera = nullptr,
                                       Matrix23* J_point = nullptr) {
  return snavelyResidual(camera, cameraRotation(camera), point, u, v, J_camera, J_point);
}

}  // namespace pnpba::bal_detail
