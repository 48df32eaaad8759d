// Robust kernels: g2o's rho against Ceres's own HuberLoss / CauchyLoss (an independent
// implementation of the same functions), and derivatives against central differences.
#include "pnpba/optimize/robust_kernel.h"

#include <ceres/loss_function.h>
#include <gtest/gtest.h>

#include "pnpba/optimize/edge_se3_project_xyz.h"

namespace pnpba {
namespace {

template <typename Kernel, typename CeresLoss>
void expectSameAsCeres(double delta) {
  const Kernel kernel(delta);
  const CeresLoss loss(delta);
  for (double s : {0.0, 1e-6, 0.3, 0.999 * delta * delta, delta * delta, 1.001 * delta * delta, 5.0,
                   100.0, 1e6}) {
    Eigen::Vector3d ours;
    kernel.robustify(s, ours);
    double theirs[3];
    loss.Evaluate(s, theirs);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(ours[k], theirs[k], 1e-12 * std::max(1.0, std::abs(theirs[k])))
          << "s=" << s << " k=" << k;
    }
  }
}

TEST(RobustKernel, HuberEqualsCeresHuberLoss) {
  expectSameAsCeres<RobustKernelHuber, ceres::HuberLoss>(1.0);
  expectSameAsCeres<RobustKernelHuber, ceres::HuberLoss>(2.447);
}

TEST(RobustKernel, CauchyEqualsCeresCauchyLoss) {
  expectSameAsCeres<RobustKernelCauchy, ceres::CauchyLoss>(1.0);
  expectSameAsCeres<RobustKernelCauchy, ceres::CauchyLoss>(3.0);
}

TEST(RobustKernel, DerivativesMatchCentralDifferences) {
  const RobustKernelHuber huber(1.7);
  const RobustKernelCauchy cauchy(0.8);
  for (const RobustKernel* k :
       {static_cast<const RobustKernel*>(&huber), static_cast<const RobustKernel*>(&cauchy)}) {
    for (double s : {0.2, 1.0, 2.5, 9.0, 40.0}) {
      const double h = 1e-5 * s;
      Eigen::Vector3d r, rp, rm;
      k->robustify(s, r);
      k->robustify(s + h, rp);
      k->robustify(s - h, rm);
      EXPECT_NEAR(r[1], (rp[0] - rm[0]) / (2 * h), 1e-7) << "s=" << s;
      EXPECT_NEAR(r[2], (rp[1] - rm[1]) / (2 * h), 1e-6) << "s=" << s;
    }
  }
}

TEST(RobustKernel, HuberIsQuadraticInsideAndLinearInSqrtOutside) {
  const RobustKernelHuber huber(2.0);
  Eigen::Vector3d r;
  huber.robustify(3.9, r);
  EXPECT_DOUBLE_EQ(r[0], 3.9);
  huber.robustify(16.0, r);               // sqrt(s) = 4
  EXPECT_DOUBLE_EQ(r[0], 2 * 2 * 4 - 4);  // 2 delta sqrt(s) - delta^2
  EXPECT_DOUBLE_EQ(r[1], 0.5);            // delta / sqrt(s): g2o's weight
}

// An edge's robust weight is the kernel's rho' at the edge's current chi2, whether or not
// robustChi2() just evaluated the kernel there (it keeps that evaluation for the solver).
TEST(RobustKernels, EdgeWeightFollowsTheErrorAndTheKernel) {
  VertexSE3Expmap pose;
  EdgeSE3ProjectXYZOnlyPose e;
  e.setVertex(0, &pose);
  e.fx = e.fy = 500, e.cx = 320, e.cy = 240;
  e.Xw = Eigen::Vector3d(0.1, -0.2, 2.0);
  e.setMeasurement(Eigen::Vector2d(360, 180));  // 25 and 10 px off
  e.setRobustKernel(new RobustKernelHuber(3.0));
  auto expected = [&e](double delta) {
    Eigen::Vector3d rho;
    RobustKernelHuber(delta).robustify(e.chi2(), rho);
    return rho[1];
  };
  e.computeError();
  e.robustChi2();
  EXPECT_DOUBLE_EQ(e.robustWeight(), expected(3.0));
  EXPECT_LT(e.robustWeight(), 1.0);
  // The error moves: the weight is evaluated afresh.
  e.Xw = Eigen::Vector3d(0.2, -0.4, 2.5);
  e.computeError();
  EXPECT_DOUBLE_EQ(e.robustWeight(), expected(3.0));
  // Another kernel at the same error.
  e.robustChi2();
  e.setRobustKernel(new RobustKernelHuber(50.0));
  EXPECT_DOUBLE_EQ(e.robustWeight(), expected(50.0));
  EXPECT_EQ(e.robustWeight(), 1.0);  // inside the wider kernel
  e.setRobustKernel(nullptr);
  EXPECT_EQ(e.robustWeight(), 1.0);
}

}  // namespace
}  // namespace pnpba
