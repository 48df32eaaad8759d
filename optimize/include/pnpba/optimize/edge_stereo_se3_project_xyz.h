// Edges for a point observed by a camera with depth (RGB-D), in g2o/ORB-SLAM's stereo form:
// the measurement is (u, v, u_r) with u_r = u - bf / z, i.e. a virtual right camera at
// baseline b (bf = baseline * fx). An RGB-D pixel (u, v) with depth z gives u_r = u - bf / z.
//   EdgeStereoSE3ProjectXYZ          vertex 0: point, vertex 1: pose
//   EdgeStereoSE3ProjectXYZOnlyPose  vertex 0: pose, the point Xw held fixed
// Why this form: the third residual is a disparity bf/z, whose noise for depth noise
// sigma_z = k z^2 is sigma_d = bf k, the same at every depth. So one constant weight models
// depth noise that grows with z^2 (the Kinect-type sensor model), and the depth residual
// makes the scale of the translation observable.
#pragma once

#include "pnpba/optimize/base_edge.h"
#include "pnpba/optimize/edge_se3_project_xyz.h"

namespace pnpba {

struct StereoIntrinsics {
  double fx = 1, fy = 1, cx = 0, cy = 0, bf = 1;
  Eigen::Vector3d project(const Eigen::Vector3d& P) const {
    const double u = fx * P.x() / P.z() + cx;
    return Eigen::Vector3d(u, fy * P.y() / P.z() + cy, u - bf / P.z());
  }
};

class EdgeStereoSE3ProjectXYZ
    : public BaseBinaryEdge<3, Eigen::Vector3d, VertexPointXYZ, VertexSE3Expmap> {
 public:
  void evaluate(const Eigen::Vector3d& X, const SE3Quat& T, ErrorVector* error, JacobianXiType* Ji,
                JacobianXjType* Jj) const override;
  bool isDepthPositive() const;
  Eigen::Vector3d cam_project(const Eigen::Vector3d& P) const { return intrinsics().project(P); }
  StereoIntrinsics intrinsics() const { return {fx, fy, cx, cy, bf}; }

  double fx = 1, fy = 1, cx = 0, cy = 0, bf = 1;
};

class EdgeStereoSE3ProjectXYZOnlyPose : public BaseUnaryEdge<3, Eigen::Vector3d, VertexSE3Expmap> {
 public:
  void evaluate(const SE3Quat& T, ErrorVector* error, JacobianXiType* Ji) const override;
  bool isDepthPositive() const;
  Eigen::Vector3d cam_project(const Eigen::Vector3d& P) const { return intrinsics().project(P); }
  StereoIntrinsics intrinsics() const { return {fx, fy, cx, cy, bf}; }

  Eigen::Vector3d Xw = Eigen::Vector3d::Zero();
  double fx = 1, fy = 1, cx = 0, cy = 0, bf = 1;
};

}  // namespace pnpba
