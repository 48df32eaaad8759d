// SE3Quat: a rigid transform stored as a unit quaternion and a translation, with g2o's
// conventions (g2o/types/slam3d/se3quat.h), so graphs written for g2o mean the same here.
//
// Conventions fixed by this file:
//   - map(X) = R X + t;  (A * B).map(X) = A.map(B.map(X)).
//   - Tangent vectors are ordered ROTATION FIRST: xi = [omega; upsilon] (g2o's order; Sophus
//     uses translation first).
//   - exp(xi) = (R(omega), V(omega) upsilon); log is its inverse, valid for rotation angles in
//     [0, pi] (unlike g2o's, which loses accuracy near pi).
//   - The quaternion is kept unit-norm with w >= 0.
//   - 7-vector layout (toVector/fromVector, as g2o): [tx ty tz qx qy qz qw].
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace pnpba {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Vector7d = Eigen::Matrix<double, 7, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

// [w]x, the matrix with skew(w) v = w x v.
Eigen::Matrix3d skew(const Eigen::Vector3d& w);

class SE3Quat {
 public:
  SE3Quat() : r_(Eigen::Quaterniond::Identity()), t_(Eigen::Vector3d::Zero()) {}
  SE3Quat(const Eigen::Matrix3d& R, const Eigen::Vector3d& t);
  SE3Quat(const Eigen::Quaterniond& q, const Eigen::Vector3d& t);

  const Eigen::Vector3d& translation() const { return t_; }
  const Eigen::Quaterniond& rotation() const { return r_; }
  void setTranslation(const Eigen::Vector3d& t) { t_ = t; }
  void setRotation(const Eigen::Quaterniond& q);

  Eigen::Vector3d map(const Eigen::Vector3d& X) const { return r_ * X + t_; }
  SE3Quat operator*(const SE3Quat& other) const;
  SE3Quat& operator*=(const SE3Quat& other);
  SE3Quat inverse() const;

  static SE3Quat exp(const Vector6d& xi);
  Vector6d log() const;

  // Adjoint: exp(adj() xi) * T == T * exp(xi), for xi in [omega; upsilon] order.
  Matrix6d adj() const;

  Vector7d toVector() const;
  static SE3Quat fromVector(const Vector7d& v);
  Eigen::Matrix4d to_homogeneous_matrix() const;
  Eigen::Isometry3d toIsometry() const;

  // Keeps |q| = 1 and w >= 0 (g2o's normalizeRotation).
  void normalizeRotation();

 private:
  Eigen::Quaterniond r_;
  Eigen::Vector3d t_;
};

}  // namespace pnpba
