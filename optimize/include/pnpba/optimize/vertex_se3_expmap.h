// VertexSE3Expmap: a camera pose T (world -> camera) with g2o's left-multiplicative update
// T <- exp(delta) * T, delta = [omega; upsilon] (rotation first).
// Parameter block (Ceres bridge): [qx qy qz qw tx ty tz].
#pragma once

#include "pnpba/optimize/base_vertex.h"
#include "pnpba/optimize/se3_quat.h"

namespace pnpba {

class VertexSE3Expmap : public BaseVertex<6, SE3Quat> {
 public:
  static constexpr int kBlockSize = 7;

  void setToOriginImpl() override { estimate_ = SE3Quat(); }
  int blockSize() const override { return kBlockSize; }
  void getBlock(double* x) const override { toBlock(estimate_, x); }
  void setBlock(const double* x) override { estimate_ = estimateFromBlock(x); }
  void blockPlus(const double* x, const double* delta, double* x_plus) const override;
  bool estimateIsFinite() const override;

  static SE3Quat estimateFromBlock(const double* x);
  static void toBlock(const SE3Quat& T, double* x);

 protected:
  void oplusImpl(const double* delta) override;
};

}  // namespace pnpba
