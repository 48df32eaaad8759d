// g2o-compatible types for "Bundle Adjustment in the Large" problems (DESIGN.md section 4).
//
// BAL camera, 9 parameters in file order: angle-axis r, translation t, focal f, radial k1, k2.
//   P = R(r) X + t;  p = -P.xy / P.z;  rho = 1 + k1 |p|^2 + k2 |p|^4;  (u, v) = f rho p
// EdgeBalProjection: e = observed - (u, v) (Ceres's example uses predicted - observed: same
// cost).
//
// VertexBalCamera: 9 dof, updated as
//   pose   <- exp(d[0:6]) * pose   (d[0:3] rotation, d[3:6] translation: g2o's order, left)
//   f, k1, k2 <- + d[6], d[7], d[8]  (additive)
// Parameter block (Ceres bridge): [qx qy qz qw tx ty tz f k1 k2].
// Analytic Jacobians: 2x9 camera block = de/dP [-[P]x | I] for the pose, then de/df,
// de/dk1, de/dk2; 2x3 point block = de/dP R (tests/optimize/edge_jacobian_test.cpp checks both
// against central differences).
#pragma once

#include <Eigen/Core>

#include "pnpba/optimize/base_edge.h"
#include "pnpba/optimize/base_vertex.h"
#include "pnpba/optimize/se3_quat.h"
#include "pnpba/optimize/vertex_point_xyz.h"

namespace pnpba {

struct BalCamera {
  SE3Quat pose;  // world -> camera
  double f = 1, k1 = 0, k2 = 0;

  // From / to the 9 file parameters [r, t, f, k1, k2].
  static BalCamera fromParameters(const double* p);
  void toParameters(double* p) const;
  // The predicted pixel of world point X (no check of P.z).
  Eigen::Vector2d project(const Eigen::Vector3d& X) const;
};

class VertexBalCamera : public BaseVertex<9, BalCamera> {
 public:
  static constexpr int kBlockSize = 10;

  void setToOriginImpl() override { estimate_ = BalCamera(); }
  int blockSize() const override { return kBlockSize; }
  void getBlock(double* x) const override { toBlock(estimate_, x); }
  void setBlock(const double* x) override { estimate_ = estimateFromBlock(x); }
  void blockPlus(const double* x, const double* delta, double* x_plus) const override;
  bool estimateIsFinite() const override;

  static BalCamera estimateFromBlock(const double* x);
  static void toBlock(const BalCamera& c, double* x);

 protected:
  void oplusImpl(const double* delta) override;
};

// Vertex 0: point (VertexPointXYZ), vertex 1: camera (VertexBalCamera).
class EdgeBalProjection
    : public BaseBinaryEdge<2, Eigen::Vector2d, VertexPointXYZ, VertexBalCamera> {
 public:
  void evaluate(const Eigen::Vector3d& X, const BalCamera& camera, ErrorVector* error,
                JacobianXiType* Ji, JacobianXjType* Jj) const override;
};

}  // namespace pnpba
