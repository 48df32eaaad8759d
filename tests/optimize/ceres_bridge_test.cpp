// The Ceres bridge: the manifold's Plus is exp(delta) * T, and the Jacobian Ceres works with
// (ambient Jacobian times PlusJacobian) equals central differences of the whitened residual
// r(exp(delta) * T), i.e. the [J 0] / [I; 0] construction is exact.
#include "ceres_bridge.h"

#include <gtest/gtest.h>

#include "pnpba/optimize/edge_se3_project_xyz.h"
#include "pnpba/optimize/edge_stereo_se3_project_xyz.h"
#include "random_poses.h"

namespace pnpba {
namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

TEST(CeresBridge, ManifoldPlusIsLeftMultiplicationByExp) {
  test::RandomScene rnd(21);
  VertexSE3Expmap prototype;
  internal::VertexManifold manifold(&prototype);
  ASSERT_EQ(manifold.AmbientSize(), 7);
  ASSERT_EQ(manifold.TangentSize(), 6);
  for (int i = 0; i < 50; ++i) {
    const SE3Quat T = rnd.pose(M_PI / 2, 2.0);
    Vector6d delta;
    delta << rnd.unitVector() * rnd.uniform(0, 1), Eigen::Vector3d::Random();
    double x[7], x_plus[7];
    VertexSE3Expmap::toBlock(T, x);
    ASSERT_TRUE(manifold.Plus(x, delta.data(), x_plus));
    const Eigen::Matrix4d want = (SE3Quat::exp(delta) * T).to_homogeneous_matrix();
    const Eigen::Matrix4d got = VertexSE3Expmap::estimateFromBlock(x_plus).to_homogeneous_matrix();
    EXPECT_LE((got - want).cwiseAbs().maxCoeff(), 1e-14);

    // And the vertex's own oplus agrees with both.
    VertexSE3Expmap v;
    v.setEstimate(T);
    v.oplus(delta.data());
    EXPECT_LE((v.estimate().to_homogeneous_matrix() - want).cwiseAbs().maxCoeff(), 1e-14);
  }
}

// Jacobian of the whitened residual w.r.t. the tangent of block `b`, by central differences
// through the manifold's Plus (or plain addition for Euclidean blocks).
Eigen::MatrixXd numericTangentJacobian(const ceres::CostFunction& cost,
                                       std::vector<std::vector<double>> blocks, size_t b,
                                       const ceres::Manifold* manifold, int tangent) {
  const int m = cost.num_residuals();
  const double h = 1e-6;
  Eigen::MatrixXd J(m, tangent);
  const std::vector<double> x0 = blocks[b];
  for (int k = 0; k < tangent; ++k) {
    Eigen::VectorXd rp(m), rm(m);
    for (double sign : {1.0, -1.0}) {
      Eigen::VectorXd delta = Eigen::VectorXd::Zero(tangent);
      delta[k] = sign * h;
      if (manifold != nullptr) {
        manifold->Plus(x0.data(), delta.data(), blocks[b].data());
      } else {
        for (int j = 0; j < tangent; ++j) blocks[b][j] = x0[j] + delta[j];
      }
      std::vector<const double*> ptrs;
      for (auto& blk : blocks) ptrs.push_back(blk.data());
      cost.Evaluate(ptrs.data(), sign > 0 ? rp.data() : rm.data(), nullptr);
    }
    J.col(k) = (rp - rm) / (2 * h);
  }
  return J;
}

TEST(CeresBridge, CeresJacobianThroughManifoldMatchesNumericDifferentiation) {
  test::RandomScene rnd(22);
  for (int i = 0; i < 50; ++i) {
    const SE3Quat T = rnd.pose(M_PI / 2, 2.0);
    VertexPointXYZ point;
    point.setEstimate(rnd.pointInFront(T, 0.3, 20.0));
    VertexSE3Expmap pose;
    pose.setEstimate(T);
    EdgeStereoSE3ProjectXYZ edge;
    edge.setVertex(0, &point);
    edge.setVertex(1, &pose);
    edge.fx = 517.3, edge.fy = 516.5, edge.cx = 318.6, edge.cy = 255.3, edge.bf = 40.0;
    edge.setMeasurement(edge.cam_project(T.map(point.estimate())) + Eigen::Vector3d(2, -1, 3));
    Eigen::Matrix3d info;
    info << 2.0, 0.3, 0.1, 0.3, 1.0, 0.2, 0.1, 0.2, 0.5;  // a full (non-diagonal) weight
    edge.setInformation(info);

    internal::EdgeCostFunction cost(&edge);
    std::vector<std::vector<double>> blocks = {std::vector<double>(3), std::vector<double>(7)};
    point.getBlock(blocks[0].data());
    pose.getBlock(blocks[1].data());
    const double* ptrs[2] = {blocks[0].data(), blocks[1].data()};
    Eigen::Vector3d r;
    RowMajor J_point(3, 3), J_pose_ambient(3, 7);
    double* jacobians[2] = {J_point.data(), J_pose_ambient.data()};
    ASSERT_TRUE(cost.Evaluate(ptrs, r.data(), jacobians));

    edge.computeError();
    EXPECT_NEAR(r.squaredNorm(), edge.chi2(), 1e-9 * edge.chi2());  // |r|^2 = e^T Omega e

    internal::VertexManifold manifold(&pose);
    RowMajor plus_jacobian(7, 6);
    manifold.PlusJacobian(blocks[1].data(), plus_jacobian.data());
    const Eigen::MatrixXd J_pose = J_pose_ambient * plus_jacobian;
    const Eigen::MatrixXd N_pose = numericTangentJacobian(cost, blocks, 1, &manifold, 6);
    const Eigen::MatrixXd N_point = numericTangentJacobian(cost, blocks, 0, nullptr, 3);
    EXPECT_LE((J_pose - N_pose).norm() / N_pose.norm(), 1e-6);
    EXPECT_LE((Eigen::MatrixXd(J_point) - N_point).norm() / N_point.norm(), 1e-6);
  }
}

}  // namespace
}  // namespace pnpba
