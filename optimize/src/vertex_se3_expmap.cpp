#include "pnpba/optimize/vertex_se3_expmap.h"

namespace pnpba {

SE3Quat VertexSE3Expmap::estimateFromBlock(const double* x) {
  return SE3Quat(Eigen::Quaterniond(x[3], x[0], x[1], x[2]), Eigen::Vector3d(x[4], x[5], x[6]));
}

void VertexSE3Expmap::toBlock(const SE3Quat& T, double* x) {
  const Eigen::Quaterniond& q = T.rotation();
  x[0] = q.x();
  x[1] = q.y();
  x[2] = q.z();
  x[3] = q.w();
  x[4] = T.translation().x();
  x[5] = T.translation().y();
  x[6] = T.translation().z();
}

void VertexSE3Expmap::blockPlus(const double* x, const double* delta, double* x_plus) const {
  const Vector6d d = Eigen::Map<const Vector6d>(delta);
  toBlock(SE3Quat::exp(d) * estimateFromBlock(x), x_plus);
}

bool VertexSE3Expmap::estimateIsFinite() const {
  return estimate_.rotation().coeffs().allFinite() && estimate_.translation().allFinite();
}

void VertexSE3Expmap::oplusImpl(const double* delta) {
  const Vector6d d = Eigen::Map<const Vector6d>(delta);
  estimate_ = SE3Quat::exp(d) * estimate_;
}

}  // namespace pnpba
