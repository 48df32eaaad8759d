// EdgeProjectXYZ2UV (g2o, types_six_dof_expmap): the textbook's edge. Vertex 0: point
// (VertexPointXYZ), vertex 1: pose (VertexSE3Expmap, world -> camera), parameter 0:
// CameraParameters (one focal length). e = z - cam_map(T.map(X)).
// Jacobians as DESIGN.md section 4 (pose tangent [omega; upsilon], left perturbation).
#pragma once

#include "pnpba/optimize/base_edge.h"
#include "pnpba/optimize/camera_parameters.h"
#include "pnpba/optimize/vertex_point_xyz.h"
#include "pnpba/optimize/vertex_se3_expmap.h"

namespace pnpba {

class EdgeProjectXYZ2UV
    : public BaseBinaryEdge<2, Eigen::Vector2d, VertexPointXYZ, VertexSE3Expmap> {
 public:
  EdgeProjectXYZ2UV() { resizeParameters(1); }
  void resolveParameter(int arg, Parameter* p) override;
  void evaluate(const Eigen::Vector3d& X, const SE3Quat& T, ErrorVector* error, JacobianXiType* Ji,
                JacobianXjType* Jj) const override;
  const CameraParameters* camera() const { return camera_; }

 private:
  const CameraParameters* camera_ = nullptr;
};

}  // namespace pnpba
