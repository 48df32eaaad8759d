// Chain-rule pieces shared by the projection edges (internal).
// For P = exp(delta) * T * X (left perturbation, delta = [omega; upsilon]):
//   dP/d(delta) = [ -[P]x | I ],   dP/dX = R.
// For e = z - pi(P) the edge's Jacobians are de/dP * dP/d(delta) and de/dP * R, which expand
// to exactly the closed forms of DESIGN.md section 4 (g2o's linearizeOplus).
#pragma once

#include <Eigen/Core>

namespace pnpba::internal {

inline Eigen::Matrix<double, 3, 6> pointByPoseTangent(const Eigen::Vector3d& P) {
  Eigen::Matrix<double, 3, 6> J;
  J << 0, P.z(), -P.y(), 1, 0, 0,  //
      -P.z(), 0, P.x(), 0, 1, 0,   //
      P.y(), -P.x(), 0, 0, 0, 1;
  return J;
}

// d(z - (fx x/z + cx, fy y/z + cy)) / dP.
inline Eigen::Matrix<double, 2, 3> pinholeErrorByPoint(const Eigen::Vector3d& P, double fx,
                                                       double fy) {
  const double iz = 1.0 / P.z();
  Eigen::Matrix<double, 2, 3> J;
  J << -fx * iz, 0, fx * P.x() * iz * iz,  //
      0, -fy * iz, fy * P.y() * iz * iz;
  return J;
}

// As pinholeErrorByPoint, with the third row for u_r = u - bf / z.
inline Eigen::Matrix<double, 3, 3> stereoErrorByPoint(const Eigen::Vector3d& P, double fx,
                                                      double fy, double bf) {
  const double iz = 1.0 / P.z();
  Eigen::Matrix<double, 3, 3> J;
  J.topRows<2>() = pinholeErrorByPoint(P, fx, fy);
  J.row(2) << -fx * iz, 0, (fx * P.x() - bf) * iz * iz;
  return J;
}

}  // namespace pnpba::internal
