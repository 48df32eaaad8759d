// SE3Quat against independent computations: Eigen's AngleAxis for exp, identities for
// composition and inverse, and exp/log round trips in every branch (theta < 1e-5, generic,
// near pi).
#include "pnpba/optimize/se3_quat.h"

#include <gtest/gtest.h>

#include <cmath>

#include "random_poses.h"

namespace pnpba {
namespace {

Vector6d twist(const Eigen::Vector3d& axis, double angle, const Eigen::Vector3d& upsilon) {
  Vector6d xi;
  xi.head<3>() = angle * axis.normalized();
  xi.tail<3>() = upsilon;
  return xi;
}

void expectLogInvertsExp(const Vector6d& xi, double tol) {
  const Vector6d back = SE3Quat::exp(xi).log();
  EXPECT_LE((back - xi).norm(), tol * std::max(1.0, xi.norm()))
      << "xi " << xi.transpose() << "\nlog " << back.transpose();
}

TEST(SE3Quat, LogInvertsExpForGenericAngles) {
  test::RandomScene rnd(1);
  for (int i = 0; i < 200; ++i) {
    const Vector6d xi =
        twist(rnd.unitVector(), rnd.uniform(1e-4, 3.0), Eigen::Vector3d::Random() * 2.0);
    expectLogInvertsExp(xi, 1e-12);
  }
}

TEST(SE3Quat, LogInvertsExpBelowTheSmallAngleThreshold) {
  test::RandomScene rnd(2);
  for (double angle : {0.0, 1e-12, 1e-9, 1e-7, 3e-6, 9.9e-6, 1.1e-5}) {
    const Vector6d xi = twist(rnd.unitVector(), angle, Eigen::Vector3d(0.3, -0.2, 1.5));
    expectLogInvertsExp(xi, 1e-12);
  }
}

TEST(SE3Quat, LogInvertsExpNearPi) {
  test::RandomScene rnd(3);
  for (double gap : {1e-2, 1e-4, 1e-6, 1e-8}) {
    const Vector6d xi = twist(rnd.unitVector(), M_PI - gap, Eigen::Vector3d(-1.0, 0.5, 0.25));
    expectLogInvertsExp(xi, 1e-8);
  }
}

TEST(SE3Quat, ExpRotationEqualsAngleAxis) {
  test::RandomScene rnd(4);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d axis = rnd.unitVector();
    const double angle = rnd.uniform(0, M_PI);
    const Eigen::Matrix3d want = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    const Eigen::Matrix3d got =
        SE3Quat::exp(twist(axis, angle, Eigen::Vector3d::Zero())).rotation().toRotationMatrix();
    EXPECT_LE((got - want).cwiseAbs().maxCoeff(), 1e-14);
  }
}

TEST(SE3Quat, InverseOfProductIsProductOfInversesReversed) {
  test::RandomScene rnd(5);
  for (int i = 0; i < 100; ++i) {
    const SE3Quat A = rnd.pose(M_PI, 3.0), B = rnd.pose(M_PI, 3.0);
    const Eigen::Matrix4d lhs = (A * B).inverse().to_homogeneous_matrix();
    const Eigen::Matrix4d rhs = (B.inverse() * A.inverse()).to_homogeneous_matrix();
    EXPECT_LE((lhs - rhs).cwiseAbs().maxCoeff(), 1e-13);
    EXPECT_LE((A * A.inverse()).to_homogeneous_matrix().isIdentity(1e-13), true);
  }
}

TEST(SE3Quat, ComposeMapsLikeMatrixProduct) {
  test::RandomScene rnd(6);
  for (int i = 0; i < 100; ++i) {
    const SE3Quat A = rnd.pose(M_PI, 3.0), B = rnd.pose(M_PI, 3.0);
    const Eigen::Vector3d X = Eigen::Vector3d::Random() * 10;
    EXPECT_LE(((A * B).map(X) - A.map(B.map(X))).norm(), 1e-12);
    const Eigen::Vector4d Xh = (A.to_homogeneous_matrix() * B.to_homogeneous_matrix()) *
                               Eigen::Vector4d(X.x(), X.y(), X.z(), 1.0);
    EXPECT_LE(((A * B).map(X) - Xh.head<3>()).norm(), 1e-12);
  }
}

TEST(SE3Quat, QuaternionKeepsNonNegativeW) {
  test::RandomScene rnd(7);
  for (int i = 0; i < 200; ++i) {
    const SE3Quat A = rnd.pose(M_PI, 1.0), B = rnd.pose(M_PI, 1.0);
    EXPECT_GE(A.rotation().w(), 0.0);
    EXPECT_GE((A * B).rotation().w(), 0.0);
    EXPECT_GE(A.inverse().rotation().w(), 0.0);
    EXPECT_GE(SE3Quat::exp(A.log()).rotation().w(), 0.0);
    EXPECT_NEAR(A.rotation().norm(), 1.0, 1e-15);
  }
  const Eigen::Quaterniond negative(-0.5, 0.5, 0.5, 0.5);
  const SE3Quat T(negative, Eigen::Vector3d::Zero());
  EXPECT_GT(T.rotation().w(), 0.0);
  EXPECT_TRUE(T.rotation().toRotationMatrix().isApprox(negative.toRotationMatrix(), 1e-15));
}

TEST(SE3Quat, AdjointMovesATwistAcrossThePose) {
  test::RandomScene rnd(8);
  for (int i = 0; i < 50; ++i) {
    const SE3Quat T = rnd.pose(M_PI / 2, 2.0);
    const Vector6d xi = twist(rnd.unitVector(), rnd.uniform(0, 1), Eigen::Vector3d::Random());
    const Eigen::Matrix4d lhs = (SE3Quat::exp(T.adj() * xi) * T).to_homogeneous_matrix();
    const Eigen::Matrix4d rhs = (T * SE3Quat::exp(xi)).to_homogeneous_matrix();
    EXPECT_LE((lhs - rhs).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(SE3Quat, SevenVectorRoundTripsInG2oLayout) {
  const SE3Quat T(Eigen::Quaterniond(0.9, 0.1, -0.3, 0.2).normalized(), Eigen::Vector3d(1, 2, 3));
  const Vector7d v = T.toVector();
  EXPECT_EQ(v.head<3>(), Eigen::Vector3d(1, 2, 3));  // [t, qx, qy, qz, qw]
  EXPECT_DOUBLE_EQ(v[6], T.rotation().w());
  const SE3Quat back = SE3Quat::fromVector(v);
  EXPECT_TRUE(back.to_homogeneous_matrix().isApprox(T.to_homogeneous_matrix(), 1e-15));
  EXPECT_TRUE(T.toIsometry().matrix().isApprox(T.to_homogeneous_matrix(), 1e-15));
}

}  // namespace
}  // namespace pnpba
