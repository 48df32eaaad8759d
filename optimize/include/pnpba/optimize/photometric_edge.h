// Direct (photometric) bundle adjustment: a point observed by a camera through the
// intensities of a 4x4 patch (DESIGN.md section 4, "Photometric edge").
//
// EdgePhotometric: vertex 0 a point Pw (VertexPointXYZ, world), vertex 1 a pose Tcw
// (VertexSE3Expmap, world -> camera; tangent ROTATION FIRST [omega; upsilon], left
// perturbation exp(delta) * Tcw: g2o's order, not Sophus's translation-first one).
//   Pc = Tcw Pw,  (u, v) = (fx x/z + cx, fy y/z + cy)
//   e_k = I_ref[k] - I(u + dx, v + dy),  k = 4 (dx + 2) + (dy + 2),  dx, dy in {-2, -1, 0, 1}
// with I the bilinear interpolation of the camera's grey image. Jacobians:
//   de_k/d(delta) = -grad I(u+dx, v+dy) * du/dPc * [-[Pc]x | I],  de_k/dPw = -grad I * du/dPc * R
// where grad I is the exact derivative of the bilinear interpolant (so the Jacobian is the
// derivative of the error the edge computes).
//
// Border handling: the edge reads images only through the bilinear lookup, which clamps every
// sample inside the image (never out of bounds). Whether an edge takes part is decided by
// patchInside() at the start of a round and kept for the round (DirectBundleAdjuster): an edge
// whose patch leaves the image is switched off (level 1) — no residual, no Jacobian — rather
// than contributing zeros, and a point cannot lower its cost by running off every image within a
// round because its set of edges does not change while it moves.
//
// Robust kernel: Huber on s = |e|^2 of the 16-vector. Its default width is sqrt of the chi2 95%
// quantile for 16 dof (26.296), i.e. an edge is down-weighted once its residual is larger than
// 95 % of edges with unit-variance intensity noise would be; the exercise uses delta = 1.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "pnpba/optimize/base_edge.h"
#include "pnpba/optimize/vertex_point_xyz.h"
#include "pnpba/optimize/vertex_se3_expmap.h"

namespace pnpba {

constexpr double kChi2_95_16dof = 26.296;

// A grey image as floats (row-major), shared by every edge of its camera (never copied).
struct GrayImage {
  int width = 0, height = 0;
  std::vector<float> pixels;
  float at(int x, int y) const { return pixels[static_cast<size_t>(y) * width + x]; }
  // Bilinear intensity at (x, y), the sample clamped inside the image; gradient optional.
  double sample(double x, double y, Eigen::Vector2d* gradient = nullptr) const;
};

using PatchVector = Eigen::Matrix<double, 16, 1>;

class EdgePhotometric : public BaseBinaryEdge<16, PatchVector, VertexPointXYZ, VertexSE3Expmap> {
 public:
  void setImage(const GrayImage* image) { image_ = image; }
  void setIntrinsics(double fx, double fy, double cx, double cy) {
    fx_ = fx, fy_ = fy, cx_ = cx, cy_ = cy;
  }
  void evaluate(const Eigen::Vector3d& Pw, const SE3Quat& Tcw, ErrorVector* error,
                JacobianXiType* Ji, JacobianXjType* Jj) const override;
  // Camera depth > 1e-6 and 2 <= u <= W-3, 2 <= v <= H-3 at the given estimates: every patch
  // pixel and its bilinear neighbours inside the image.
  bool patchInside(const Eigen::Vector3d& Pw, const SE3Quat& Tcw) const;
  bool patchInside() const { return patchInside(vi()->estimate(), vj()->estimate()); }

 private:
  const GrayImage* image_ = nullptr;
  double fx_ = 1, fy_ = 1, cx_ = 0, cy_ = 0;
};

}  // namespace pnpba
