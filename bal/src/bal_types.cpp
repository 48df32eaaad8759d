#include "pnpba/bal/bal_types.h"

namespace pnpba {

BalCamera BalCamera::fromParameters(const double* p) {
  const Eigen::Vector3d r(p[0], p[1], p[2]);
  const double angle = r.norm();
  const Eigen::Matrix3d R = angle > 0 ? Eigen::AngleAxisd(angle, r / angle).toRotationMatrix()
                                      : Eigen::Matrix3d::Identity();
  BalCamera c;
  c.pose = SE3Quat(R, Eigen::Vector3d(p[3], p[4], p[5]));
  c.f = p[6], c.k1 = p[7], c.k2 = p[8];
  return c;
}

void BalCamera::toParameters(double* p) const {
  const Eigen::AngleAxisd aa(pose.rotation());
  const Eigen::Vector3d r = aa.angle() * aa.axis();
  for (int i = 0; i < 3; ++i) {
    p[i] = r[i];
    p[3 + i] = pose.translation()[i];
  }
  p[6] = f, p[7] = k1, p[8] = k2;
}

Eigen::Vector2d BalCamera::project(const Eigen::Vector3d& X) const {
  const Eigen::Vector3d P = pose.map(X);
  const Eigen::Vector2d p = -P.head<2>() / P.z();
  const double r2 = p.squaredNorm();
  return f * (1.0 + k1 * r2 + k2 * r2 * r2) * p;
}

BalCamera VertexBalCamera::estimateFromBlock(const double* x) {
  BalCamera c;
  c.pose = SE3Quat(Eigen::Quaterniond(x[3], x[0], x[1], x[2]), Eigen::Vector3d(x[4], x[5], x[6]));
  c.f = x[7], c.k1 = x[8], c.k2 = x[9];
  return c;
}

void VertexBalCamera::toBlock(const BalCamera& c, double* x) {
  const Eigen::Quaterniond& q = c.pose.rotation();
  x[0] = q.x(), x[1] = q.y(), x[2] = q.z(), x[3] = q.w();
  x[4] = c.pose.translation().x(), x[5] = c.pose.translation().y(), x[6] = c.pose.translation().z();
  x[7] = c.f, x[8] = c.k1, x[9] = c.k2;
}

void VertexBalCamera::blockPlus(const double* x, const double* delta, double* x_plus) const {
  BalCamera c = estimateFromBlock(x);
  c.pose = SE3Quat::exp(Eigen::Map<const Vector6d>(delta)) * c.pose;
  c.f += delta[6], c.k1 += delta[7], c.k2 += delta[8];
  toBlock(c, x_plus);
}

bool VertexBalCamera::estimateIsFinite() const {
  return estimate_.pose.rotation().coeffs().allFinite() &&
         estimate_.pose.translation().allFinite() && std::isfinite(estimate_.f) &&
         std::isfinite(estimate_.k1) && std::isfinite(estimate_.k2);
}

void VertexBalCamera::oplusImpl(const double* delta) {
  estimate_.pose = SE3Quat::exp(Eigen::Map<const Vector6d>(delta)) * estimate_.pose;
  estimate_.f += delta[6], estimate_.k1 += delta[7], estimate_.k2 += delta[8];
}

void EdgeBalProjection::evaluate(const Eigen::Vector3d& X, const BalCamera& c, ErrorVector* error,
                                 JacobianXiType* Ji, JacobianXjType* Jj) const {
  const Eigen::Vector3d P = c.pose.map(X);
  const double iz = 1.0 / P.z();
  const Eigen::Vector2d p = -P.head<2>() * iz;
  const double r2 = p.squaredNorm();
  const double rho = 1.0 + c.k1 * r2 + c.k2 * r2 * r2;
  *error = measurement_ - c.f * rho * p;
  if (Ji == nullptr && Jj == nullptr) return;
  // d(pred)/dp = f (rho I + 2 rho' p p^T), rho' = d rho / d r2; dp/dP = -[I/z | -xy/z^2].
  const double drho = c.k1 + 2.0 * c.k2 * r2;
  const Eigen::Matrix2d dpred_dp =
      c.f * (rho * Eigen::Matrix2d::Identity() + 2.0 * drho * p * p.transpose());
  Eigen::Matrix<double, 2, 3> dp_dP;
  dp_dP << -iz, 0, P.x() * iz * iz,  //
      0, -iz, P.y() * iz * iz;
  const Eigen::Matrix<double, 2, 3> de_dP = -dpred_dp * dp_dP;
  if (Ji != nullptr) *Ji = de_dP * c.pose.rotation().toRotationMatrix();
  if (Jj != nullptr) {
    for (int r = 0; r < 2; ++r) {
      const Eigen::Vector3d a = de_dP.row(r).transpose();
      Jj->row(r).head<3>() = P.cross(a).transpose();
      Jj->row(r).segment<3>(3) = a.transpose();
    }
    Jj->col(6) = -rho * p;
    Jj->col(7) = -c.f * r2 * p;
    Jj->col(8) = -c.f * r2 * r2 * p;
  }
}

}  // namespace pnpba
