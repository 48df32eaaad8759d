// VertexPointXYZ: a 3D point with the additive update X <- X + delta. Parameter block: [x y z].
#pragma once

#include <Eigen/Core>

#include "pnpba/optimize/base_vertex.h"

namespace pnpba {

class VertexPointXYZ : public BaseVertex<3, Eigen::Vector3d> {
 public:
  static constexpr int kBlockSize = 3;

  VertexPointXYZ() { estimate_.setZero(); }
  void setToOriginImpl() override { estimate_.setZero(); }
  int blockSize() const override { return kBlockSize; }
  void getBlock(double* x) const override {
    for (int i = 0; i < 3; ++i) x[i] = estimate_[i];
  }
  void setBlock(const double* x) override { estimate_ = Eigen::Map<const Eigen::Vector3d>(x); }
  void blockPlus(const double* x, const double* delta, double* x_plus) const override {
    for (int i = 0; i < 3; ++i) x_plus[i] = x[i] + delta[i];
  }
  bool estimateIsFinite() const override { return estimate_.allFinite(); }

  static Eigen::Vector3d estimateFromBlock(const double* x) {
    return Eigen::Map<const Eigen::Vector3d>(x);
  }

 protected:
  void oplusImpl(const double* delta) override {
    estimate_ += Eigen::Map<const Eigen::Vector3d>(delta);
  }
};

// The name older g2o (and the textbook) uses for the same vertex.
using VertexSBAPointXYZ = VertexPointXYZ;

}  // namespace pnpba
