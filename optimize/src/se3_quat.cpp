// SE3 exponential and logarithm with g2o's formulas (DESIGN.md section 4), plus a logarithm
// that stays accurate near pi by working from the quaternion rather than from trace(R).
#include "pnpba/optimize/se3_quat.h"

#include <cmath>

namespace pnpba {

namespace {
// Below this rotation angle exp() uses g2o's second-order series (DESIGN.md section 4).
constexpr double kSmallAngle = 1e-5;
}  // namespace

Eigen::Matrix3d skew(const Eigen::Vector3d& w) {
  Eigen::Matrix3d S;
  S << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return S;
}

SE3Quat::SE3Quat(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) : r_(R), t_(t) {
  normalizeRotation();
}

SE3Quat::SE3Quat(const Eigen::Quaterniond& q, const Eigen::Vector3d& t) : r_(q), t_(t) {
  normalizeRotation();
}

void SE3Quat::setRotation(const Eigen::Quaterniond& q) {
  r_ = q;
  normalizeRotation();
}

void SE3Quat::normalizeRotation() {
  if (r_.w() < 0) r_.coeffs() *= -1;
  r_.normalize();
}

SE3Quat SE3Quat::operator*(const SE3Quat& other) const {
  SE3Quat result(*this);
  result *= other;
  return result;
}

SE3Quat& SE3Quat::operator*=(const SE3Quat& other) {
  t_ += r_ * other.t_;
  r_ = r_ * other.r_;
  normalizeRotation();
  return *this;
}

SE3Quat SE3Quat::inverse() const {
  SE3Quat result;
  result.r_ = r_.conjugate();
  result.t_ = result.r_ * (-t_);
  result.normalizeRotation();
  return result;
}

SE3Quat SE3Quat::exp(const Vector6d& xi) {
  const Eigen::Vector3d omega = xi.head<3>();
  const Eigen::Vector3d upsilon = xi.tail<3>();
  const double theta = omega.norm();
  const Eigen::Matrix3d Omega = skew(omega);
  const Eigen::Matrix3d Omega2 = Omega * Omega;
  Eigen::Matrix3d R;
  Eigen::Matrix3d V;
  if (theta < kSmallAngle) {
    R = Eigen::Matrix3d::Identity() + Omega + 0.5 * Omega2;
    V = Eigen::Matrix3d::Identity() + 0.5 * Omega + (1.0 / 6.0) * Omega2;
  } else {
    // g2o's closed forms, with two coefficients evaluated without cancellation:
    // (1 - cos t)/t^2 = 2 sin^2(t/2)/t^2, and (t - sin t)/t^3 by its series for small t.
    const double theta2 = theta * theta;
    const double half_sin = std::sin(0.5 * theta) / theta;
    const double a = std::sin(theta) / theta;
    const double b = 2.0 * half_sin * half_sin;
    const double c = theta < 1e-2 ? 1.0 / 6.0 - theta2 / 120.0 + theta2 * theta2 / 5040.0
                                  : (theta - std::sin(theta)) / (theta2 * theta);
    R = Eigen::Matrix3d::Identity() + a * Omega + b * Omega2;
    V = Eigen::Matrix3d::Identity() + b * Omega + c * Omega2;
  }
  return SE3Quat(Eigen::Quaterniond(R), V * upsilon);
}

Vector6d SE3Quat::log() const {
  // Rotation angle from the quaternion: theta = 2 atan2(|v|, w), with w >= 0 so theta <= pi.
  // atan2 keeps full precision at both ends, where acos(trace) does not.
  const Eigen::Vector3d v = r_.vec();
  const double vnorm = v.norm();
  const double w = r_.w();
  const double theta = 2.0 * std::atan2(vnorm, w);
  Eigen::Vector3d omega;
  if (vnorm < 1e-12) {
    omega = (2.0 / w) * v;  // theta ~ 2|v|/w; series of 2 atan2(n, w)/n
  } else {
    omega = (theta / vnorm) * v;
  }
  const Eigen::Matrix3d Omega = skew(omega);
  // V^-1 = I - Omega/2 + (1 - theta/(2 tan(theta/2))) / theta^2 * Omega^2.
  double coeff;
  if (theta < 1e-4) {
    coeff = 1.0 / 12.0 + theta * theta / 720.0;
  } else {
    const double half = 0.5 * theta;
    // theta/(2 tan(theta/2)) = half * cos(half) / sin(half), finite up to theta = pi.
    coeff = (1.0 - half * std::cos(half) / std::sin(half)) / (theta * theta);
  }
  const Eigen::Matrix3d V_inv = Eigen::Matrix3d::Identity() - 0.5 * Omega + coeff * Omega * Omega;
  Vector6d xi;
  xi.head<3>() = omega;
  xi.tail<3>() = V_inv * t_;
  return xi;
}

Matrix6d SE3Quat::adj() const {
  const Eigen::Matrix3d R = r_.toRotationMatrix();
  Matrix6d A;
  A.topLeftCorner<3, 3>() = R;
  A.topRightCorner<3, 3>().setZero();
  A.bottomLeftCorner<3, 3>() = skew(t_) * R;
  A.bottomRightCorner<3, 3>() = R;
  return A;
}

Vector7d SE3Quat::toVector() const {
  Vector7d v;
  v.head<3>() = t_;
  v.tail<4>() = r_.coeffs();  // Eigen's coeffs() order is (x, y, z, w)
  return v;
}

SE3Quat SE3Quat::fromVector(const Vector7d& v) {
  return SE3Quat(Eigen::Quaterniond(v[6], v[3], v[4], v[5]), v.head<3>());
}

Eigen::Matrix4d SE3Quat::to_homogeneous_matrix() const {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = r_.toRotationMatrix();
  T.topRightCorner<3, 1>() = t_;
  return T;
}

Eigen::Isometry3d SE3Quat::toIsometry() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = r_.toRotationMatrix();
  T.translation() = t_;
  return T;
}

}  // namespace pnpba
