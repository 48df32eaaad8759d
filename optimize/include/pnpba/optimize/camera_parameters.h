// CameraParameters: g2o's single-focal pinhole parameter, shared by EdgeProjectXYZ2UV edges
// through SparseOptimizer::addParameter and Edge::setParameterId.
//   cam_map(P)    = f * P.xy / P.z + (cx, cy)
//   stereocam_uvu_map(P) = (u, v, u - baseline * f / P.z)
#pragma once

#include <Eigen/Core>

#include "pnpba/optimize/optimizable_graph.h"

namespace pnpba {

class CameraParameters : public Parameter {
 public:
  CameraParameters() = default;
  CameraParameters(double focal_length, const Eigen::Vector2d& principle_point, double baseline)
      : focal_length(focal_length), principle_point(principle_point), baseline(baseline) {}

  Eigen::Vector2d cam_map(const Eigen::Vector3d& P) const {
    return focal_length * P.head<2>() / P.z() + principle_point;
  }
  Eigen::Vector3d stereocam_uvu_map(const Eigen::Vector3d& P) const {
    const Eigen::Vector2d uv = cam_map(P);
    return Eigen::Vector3d(uv.x(), uv.y(), uv.x() - baseline * focal_length / P.z());
  }

  double focal_length = 1.0;
  Eigen::Vector2d principle_point = Eigen::Vector2d::Zero();
  double baseline = 0.5;
};

}  // namespace pnpba
