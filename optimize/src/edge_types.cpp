// evaluate() of the projection edges: error z - pi(T X) and, on request, its Jacobians.
#include <string>
#include <typeinfo>

#include "pnpba/core/error.h"
#include "pnpba/optimize/edge_project_xyz2uv.h"
#include "pnpba/optimize/edge_se3_project_xyz.h"
#include "pnpba/optimize/edge_stereo_se3_project_xyz.h"
#include "pnpba/optimize/projection_jacobians.h"

namespace pnpba {

using internal::pinholeErrorByPoint;
using internal::stereoErrorByPoint;

namespace {

// Shared body of every projection edge: P = T X, e = z - project(P), and the Jacobians
// de/dP * [-[P]x | I] (pose) and de/dP * R (point).
template <int D, typename Project, typename ErrorByPoint>
void projectionError(const Eigen::Matrix<double, D, 1>& z, const SE3Quat& T,
                     const Eigen::Vector3d& X, const Project& project,
                     const ErrorByPoint& error_by_point, Eigen::Matrix<double, D, 1>* error,
                     Eigen::Matrix<double, D, 3>* J_point, Eigen::Matrix<double, D, 6>* J_pose) {
  // A camera at the identity (the first camera of a two-view graph, usually fixed) skips the
  // rotation: with q = (0, 0, 0, 1), q X and J R are X and J, the same values.
  const bool identity = T.rotation().coeffs() == Eigen::Vector4d(0, 0, 0, 1);
  const Eigen::Vector3d P = identity ? Eigen::Vector3d(X + T.translation()) : T.map(X);
  *error = z - project(P);
  if (J_point == nullptr && J_pose == nullptr) return;
  const Eigen::Matrix<double, D, 3> J_P = error_by_point(P);
  if (J_pose != nullptr) {
    // Row r of J_P * [-[P]x | I] is [(P x a_r)^T, a_r^T] with a_r = row r of J_P: the same as
    // J_P * pointByPoseTangent(P), without the 3x6 product.
    for (int r = 0; r < D; ++r) {
      const Eigen::Vector3d a = J_P.row(r).transpose();
      J_pose->row(r) << P.cross(a).transpose(), a.transpose();
    }
  }
  if (J_point != nullptr) {
    *J_point = identity ? J_P : Eigen::Matrix<double, D, 3>(J_P * T.rotation().toRotationMatrix());
  }
}

}  // namespace

void EdgeProjectXYZ2UV::resolveParameter(int arg, Parameter* p) {
  // The exact type is the common case and a type comparison is a fraction of a dynamic_cast,
  // which every edge pays once per initializeOptimization.
  if (arg == 0 && p != nullptr && typeid(*p) == typeid(CameraParameters)) {
    camera_ = static_cast<const CameraParameters*>(p);
    return;
  }
  camera_ = arg == 0 ? dynamic_cast<const CameraParameters*>(p) : nullptr;
  if (camera_ == nullptr) {
    throw Error("edge " + std::to_string(id()) + ": parameter " + std::to_string(arg) +
                " must be a CameraParameters");
  }
}

void EdgeProjectXYZ2UV::evaluate(const Eigen::Vector3d& X, const SE3Quat& T, ErrorVector* error,
                                 JacobianXiType* Ji, JacobianXjType* Jj) const {
  const double f = camera_->focal_length;
  projectionError<2>(
      measurement_, T, X, [this](const Eigen::Vector3d& P) { return camera_->cam_map(P); },
      [f](const Eigen::Vector3d& P) { return pinholeErrorByPoint(P, f, f); }, error, Ji, Jj);
}

void EdgeSE3ProjectXYZ::evaluate(const Eigen::Vector3d& X, const SE3Quat& T, ErrorVector* error,
                                 JacobianXiType* Ji, JacobianXjType* Jj) const {
  const PinholeIntrinsics k = intrinsics();
  projectionError<2>(
      measurement_, T, X, [&k](const Eigen::Vector3d& P) { return k.project(P); },
      [&k](const Eigen::Vector3d& P) { return pinholeErrorByPoint(P, k.fx, k.fy); }, error, Ji, Jj);
}

bool EdgeSE3ProjectXYZ::isDepthPositive() const {
  return vj()->estimate().map(vi()->estimate()).z() > 0.0;
}

void EdgeSE3ProjectXYZOnlyPose::evaluate(const SE3Quat& T, ErrorVector* error,
                                         JacobianXiType* Ji) const {
  const PinholeIntrinsics k = intrinsics();
  projectionError<2>(
      measurement_, T, Xw, [&k](const Eigen::Vector3d& P) { return k.project(P); },
      [&k](const Eigen::Vector3d& P) { return pinholeErrorByPoint(P, k.fx, k.fy); }, error, nullptr,
      Ji);
}

bool EdgeSE3ProjectXYZOnlyPose::isDepthPositive() const {
  return vi()->estimate().map(Xw).z() > 0.0;
}

void EdgeStereoSE3ProjectXYZ::evaluate(const Eigen::Vector3d& X, const SE3Quat& T,
                                       ErrorVector* error, JacobianXiType* Ji,
                                       JacobianXjType* Jj) const {
  const StereoIntrinsics k = intrinsics();
  projectionError<3>(
      measurement_, T, X, [&k](const Eigen::Vector3d& P) { return k.project(P); },
      [&k](const Eigen::Vector3d& P) { return stereoErrorByPoint(P, k.fx, k.fy, k.bf); }, error, Ji,
      Jj);
}

bool EdgeStereoSE3ProjectXYZ::isDepthPositive() const {
  return vj()->estimate().map(vi()->estimate()).z() > 0.0;
}

void EdgeStereoSE3ProjectXYZOnlyPose::evaluate(const SE3Quat& T, ErrorVector* error,
                                               JacobianXiType* Ji) const {
  const StereoIntrinsics k = intrinsics();
  projectionError<3>(
      measurement_, T, Xw, [&k](const Eigen::Vector3d& P) { return k.project(P); },
      [&k](const Eigen::Vector3d& P) { return stereoErrorByPoint(P, k.fx, k.fy, k.bf); }, error,
      nullptr, Ji);
}

bool EdgeStereoSE3ProjectXYZOnlyPose::isDepthPositive() const {
  return vi()->estimate().map(Xw).z() > 0.0;
}

}  // namespace pnpba
