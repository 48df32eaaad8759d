// ORB-SLAM's g2o edges with separate focal lengths (fx for u, fy for v):
//   EdgeSE3ProjectXYZ          vertex 0: point, vertex 1: pose;  e = z - pi(T X)
//   EdgeSE3ProjectXYZOnlyPose  vertex 0: pose, the point Xw held fixed (motion-only BA)
// with pi(P) = (fx x/z + cx, fy y/z + cy). Pose tangent [omega; upsilon], left perturbation.
#pragma once

#include "pnpba/optimize/base_edge.h"
#include "pnpba/optimize/vertex_point_xyz.h"
#include "pnpba/optimize/vertex_se3_expmap.h"

namespace pnpba {

// Pinhole intrinsics carried by an edge (ORB-SLAM style: members, no parameter slot).
struct PinholeIntrinsics {
  double fx = 1, fy = 1, cx = 0, cy = 0;
  Eigen::Vector2d project(const Eigen::Vector3d& P) const {
    return Eigen::Vector2d(fx * P.x() / P.z() + cx, fy * P.y() / P.z() + cy);
  }
};

class EdgeSE3ProjectXYZ
    : public BaseBinaryEdge<2, Eigen::Vector2d, VertexPointXYZ, VertexSE3Expmap> {
 public:
  void evaluate(const Eigen::Vector3d& X, const SE3Quat& T, ErrorVector* error, JacobianXiType* Ji,
                JacobianXjType* Jj) const override;
  // Is the point in front of the camera at the current estimates?
  bool isDepthPositive() const;
  Eigen::Vector2d cam_project(const Eigen::Vector3d& P) const { return intrinsics().project(P); }
  PinholeIntrinsics intrinsics() const { return {fx, fy, cx, cy}; }

  double fx = 1, fy = 1, cx = 0, cy = 0;
};

class EdgeSE3ProjectXYZOnlyPose : public BaseUnaryEdge<2, Eigen::Vector2d, VertexSE3Expmap> {
 public:
  void evaluate(const SE3Quat& T, ErrorVector* error, JacobianXiType* Ji) const override;
  bool isDepthPositive() const;
  Eigen::Vector2d cam_project(const Eigen::Vector3d& P) const { return intrinsics().project(P); }
  PinholeIntrinsics intrinsics() const { return {fx, fy, cx, cy}; }

  Eigen::Vector3d Xw = Eigen::Vector3d::Zero();
  double fx = 1, fy = 1, cx = 0, cy = 0;
};

}  // namespace pnpba
