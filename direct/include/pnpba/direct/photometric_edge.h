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

// The image and camera an edge reads, and the photometric error itself (shared by both point
// parameterisations).
class PhotometricObservation {
 public:
  virtual ~PhotometricObservation() = default;
  void setImage(const GrayImage* image) { image_ = image; }
  void setIntrinsics(double fx, double fy, double cx, double cy) {
    fx_ = fx, fy_ = fy, cx_ = cx, cy_ = cy;
  }
  // Camera depth > 1e-6 and 2 <= u <= W-3, 2 <= v <= H-3: every patch pixel and its bilinear
  // neighbours inside the image.
  bool patchInside(const Eigen::Vector3d& Pw, const SE3Quat& Tcw) const;
  // At the edge's current estimates.
  virtual bool patchInside() const = 0;

 protected:
  // e = patch - I(...), with de/dPw (16x3) and de/d(delta pose) (16x6) when requested.
  void photometricError(const PatchVector& patch, const Eigen::Vector3d& Pw, const SE3Quat& Tcw,
                        PatchVector* error, Eigen::Matrix<double, 16, 3>* J_Pw,
                        Eigen::Matrix<double, 16, 6>* J_pose) const;

 private:
  const GrayImage* image_ = nullptr;
  double fx_ = 1, fy_ = 1, cx_ = 0, cy_ = 0;
};

// Point in world coordinates (3 dof, additive).
class EdgePhotometric : public BaseBinaryEdge<16, PatchVector, VertexPointXYZ, VertexSE3Expmap>,
                        public PhotometricObservation {
 public:
  void evaluate(const Eigen::Vector3d& Pw, const SE3Quat& Tcw, ErrorVector* error,
                JacobianXiType* Ji, JacobianXjType* Jj) const override {
    photometricError(measurement_, Pw, Tcw, error, Ji, Jj);
  }
  using PhotometricObservation::patchInside;
  bool patchInside() const override { return patchInside(vi()->estimate(), vj()->estimate()); }
};

// Inverse-depth point relative to a host camera T_hw (held fixed): q = (a, b, rho) with
// X_host = (a, b, 1) / rho, updated additively (3 dof: bearing and inverse depth). The host's
// own edges stay free (a, b move too), unlike a 1-dof inverse depth along a fixed ray.
class VertexInverseDepthPoint : public BaseVertex<3, Eigen::Vector3d> {
 public:
  static constexpr int kBlockSize = 3;
  VertexInverseDepthPoint() { estimate_ = Eigen::Vector3d(0, 0, 1); }
  void setToOriginImpl() override { estimate_ = Eigen::Vector3d(0, 0, 1); }
  int blockSize() const override { return kBlockSize; }
  void getBlock(double* x) const override {
    for (int i = 0; i < 3; ++i) x[i] = estimate_[i];
  }
  void setBlock(const double* x) override { estimate_ = Eigen::Vector3d(x[0], x[1], x[2]); }
  void blockPlus(const double* x, const double* d, double* out) const override {
    for (int i = 0; i < 3; ++i) out[i] = x[i] + d[i];
  }
  bool estimateIsFinite() const override { return estimate_.allFinite(); }
  static Eigen::Vector3d estimateFromBlock(const double* x) {
    return Eigen::Vector3d(x[0], x[1], x[2]);
  }

 protected:
  void oplusImpl(const double* d) override { estimate_ += Eigen::Vector3d(d[0], d[1], d[2]); }
};

class EdgePhotometricInverseDepth
    : public BaseBinaryEdge<16, PatchVector, VertexInverseDepthPoint, VertexSE3Expmap>,
      public PhotometricObservation {
 public:
  void setHost(const SE3Quat& T_hw) { T_wh_ = T_hw.inverse(); }
  Eigen::Vector3d worldPoint(const Eigen::Vector3d& q) const {
    return T_wh_.map(Eigen::Vector3d(q.x(), q.y(), 1.0) / q.z());
  }
  void evaluate(const Eigen::Vector3d& q, const SE3Quat& Tcw, ErrorVector* error,
                JacobianXiType* Ji, JacobianXjType* Jj) const override;
  using PhotometricObservation::patchInside;
  bool patchInside() const override {
    return patchInside(worldPoint(vi()->estimate()), vj()->estimate());
  }

 private:
  SE3Quat T_wh_;
};

}  // namespace pnpba
