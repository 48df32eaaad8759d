#include "pnpba/direct/photometric_edge.h"

#include <algorithm>
#include <cmath>

#include "pnpba/optimize/projection_jacobians.h"

namespace pnpba {

double GrayImage::sample(double x, double y, Eigen::Vector2d* gradient) const {
  // Clamp so that (x0 + 1, y0 + 1) is still a pixel: no read outside the image, ever.
  x = std::clamp(x, 0.0, width - 1.000001);
  y = std::clamp(y, 0.0, height - 1.000001);
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const double ax = x - x0, ay = y - y0;
  const double i00 = at(x0, y0), i10 = at(x0 + 1, y0), i01 = at(x0, y0 + 1),
               i11 = at(x0 + 1, y0 + 1);
  if (gradient != nullptr) {
    (*gradient)[0] = (1 - ay) * (i10 - i00) + ay * (i11 - i01);
    (*gradient)[1] = (1 - ax) * (i01 - i00) + ax * (i11 - i10);
  }
  return (1 - ax) * (1 - ay) * i00 + ax * (1 - ay) * i10 + (1 - ax) * ay * i01 + ax * ay * i11;
}

bool PhotometricObservation::patchInside(const Eigen::Vector3d& Pw, const SE3Quat& Tcw) const {
  const Eigen::Vector3d P = Tcw.map(Pw);
  if (!(P.z() > 1e-6)) return false;
  const double u = fx_ * P.x() / P.z() + cx_, v = fy_ * P.y() / P.z() + cy_;
  return u >= 2 && u <= image_->width - 3 && v >= 2 && v <= image_->height - 3;
}

void PhotometricObservation::photometricError(const PatchVector& patch, const Eigen::Vector3d& Pw,
                                              const SE3Quat& Tcw, PatchVector* error,
                                              Eigen::Matrix<double, 16, 3>* Ji,
                                              Eigen::Matrix<double, 16, 6>* Jj) const {
  const Eigen::Vector3d P = Tcw.map(Pw);
  const double iz = 1.0 / P.z();
  const double u = fx_ * P.x() * iz + cx_, v = fy_ * P.y() * iz + cy_;
  const bool jacobians = Ji != nullptr || Jj != nullptr;
  // du/dPc (2x3) and its products with the tangent and point directions, shared by all pixels.
  Eigen::Matrix<double, 2, 3> du_dP;
  du_dP << fx_ * iz, 0, -fx_ * P.x() * iz * iz, 0, fy_ * iz, -fy_ * P.y() * iz * iz;
  Eigen::Matrix<double, 2, 6> du_dpose = Eigen::Matrix<double, 2, 6>::Zero();
  Eigen::Matrix<double, 2, 3> du_dpoint = Eigen::Matrix<double, 2, 3>::Zero();
  if (jacobians) {
    du_dpose = du_dP * internal::pointByPoseTangent(P);
    du_dpoint = du_dP * Tcw.rotation().toRotationMatrix();
  }
  Eigen::Vector2d grad = Eigen::Vector2d::Zero();
  for (int dx = -2; dx <= 1; ++dx) {
    for (int dy = -2; dy <= 1; ++dy) {
      const int k = 4 * (dx + 2) + (dy + 2);
      const double I = image_->sample(u + dx, v + dy, jacobians ? &grad : nullptr);
      (*error)[k] = patch[k] - I;
      if (Jj != nullptr) Jj->row(k) = -grad.transpose() * du_dpose;
      if (Ji != nullptr) Ji->row(k) = -grad.transpose() * du_dpoint;
    }
  }
}

}  // namespace pnpba

namespace pnpba {

void EdgePhotometricInverseDepth::evaluate(const Eigen::Vector3d& q, const SE3Quat& Tcw,
                                           ErrorVector* error, JacobianXiType* Ji,
                                           JacobianXjType* Jj) const {
  Eigen::Matrix<double, 16, 3> J_Pw;
  photometricError(measurement_, worldPoint(q), Tcw, error, Ji != nullptr ? &J_Pw : nullptr, Jj);
  if (Ji == nullptr) return;
  // dPw/dq = R_wh * d(X_host)/dq, X_host = (a, b, 1) / rho.
  const double r = q.z();
  Eigen::Matrix3d dX;
  dX << 1 / r, 0, -q.x() / (r * r), 0, 1 / r, -q.y() / (r * r), 0, 0, -1 / (r * r);
  *Ji = J_Pw * (T_wh_.rotation().toRotationMatrix() * dX);
}

}  // namespace pnpba
