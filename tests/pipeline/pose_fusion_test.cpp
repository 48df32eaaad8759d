// Fusing two agreeing pose estimates (pose_fusion.h): against a Monte Carlo of independent
// estimators with known covariances, and the shared calibration term's weights.
#include "pnpba/pipeline/pose_fusion.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <random>

namespace pnpba {
namespace {

SE3Quat truthPose() {
  return SE3Quat(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 0.5).normalized())),
      Eigen::Vector3d(0.3, -0.1, 0.8));
}

// A random covariance with sigmas of about `scale`, correlated between its axes.
Matrix6d randomCovariance(std::mt19937* rng, double scale) {
  std::normal_distribution<double> n(0.0, 1.0);
  Matrix6d A;
  for (int i = 0; i < 36; ++i) A(i) = n(*rng);
  return scale * scale * (A * A.transpose() / 6.0 + 0.2 * Matrix6d::Identity());
}

Vector6d draw(const Matrix6d& covariance, std::mt19937* rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Vector6d z;
  for (int i = 0; i < 6; ++i) z(i) = n(*rng);
  return Eigen::LLT<Matrix6d>(covariance).matrixL() * z;
}

PoseEstimate estimate(const SE3Quat& T, const Matrix6d& C) {
  PoseEstimate e;
  e.T_21 = T;
  e.own = e.judged = e.nominal = C;
  return e;
}

TEST(PoseFusion, TheFusedCovarianceIsTheFusedErrorsOwn) {
  std::mt19937 rng(7);
  const Matrix6d Ca = randomCovariance(&rng, 0.004), Cb = randomCovariance(&rng, 0.006);
  const SE3Quat T = truthPose();
  constexpr int kDraws = 4000;
  Matrix6d scatter = Matrix6d::Zero();
  double nees = 0;
  Matrix6d reported = Matrix6d::Zero();
  for (int i = 0; i < kDraws; ++i) {
    const PoseEstimate a = estimate(SE3Quat::exp(draw(Ca, &rng)) * T, Ca);
    const PoseEstimate b = estimate(SE3Quat::exp(draw(Cb, &rng)) * T, Cb);
    PoseEstimate f;
    ASSERT_TRUE(fusePoseEstimates(a, b, &f));
    const Vector6d d = (f.T_21 * T.inverse()).log();
    scatter += d * d.transpose() / kDraws;
    nees += d.dot(f.own.ldlt().solve(d)) / kDraws;
    reported = f.own;
  }
  // The independent computation: the information-weighted mean's covariance (Ca^-1 + Cb^-1)^-1.
  const Matrix6d expected = (Ca.inverse() + Cb.inverse()).inverse();
  EXPECT_LT((reported - expected).norm(), 1e-9 * expected.norm());
  EXPECT_LT((scatter - expected).norm(), 0.1 * expected.norm());
  EXPECT_NEAR(nees, 6.0, 0.35);  // chi2(6) mean; its sampling sigma is 0.055 here
  // Better than either estimate alone.
  EXPECT_LT(expected.trace(), std::min(Ca.trace(), Cb.trace()));
}

TEST(PoseFusion, EqualEstimatesHalveTheCovarianceAndKeepThePose) {
  std::mt19937 rng(3);
  const Matrix6d C = randomCovariance(&rng, 0.01);
  PoseEstimate f;
  ASSERT_TRUE(fusePoseEstimates(estimate(truthPose(), C), estimate(truthPose(), C), &f));
  EXPECT_LT((f.own - 0.5 * C).norm(), 1e-12);
  EXPECT_LT((f.judged - 0.5 * C).norm(), 1e-12);
  EXPECT_LT((f.T_21 * truthPose().inverse()).log().norm(), 1e-12);
}

TEST(PoseFusion, ThePoseLiesWhereTheInformationPullsIt) {
  // One estimate a hundred times surer than the other: the fusion lies 1/101 of the way to the
  // uncertain one.
  const Matrix6d sure = 1e-6 * Matrix6d::Identity();
  Vector6d offset;
  offset << 0.01, 0, 0, 0, 0.05, 0;
  const SE3Quat far = SE3Quat::exp(offset) * truthPose();
  PoseEstimate f;
  ASSERT_TRUE(fusePoseEstimates(estimate(truthPose(), sure), estimate(far, 100 * sure), &f));
  const Vector6d moved = (f.T_21 * truthPose().inverse()).log();
  EXPECT_LT((moved - offset / 101).norm(), 1e-9);
}

TEST(PoseFusion, TheCalibrationTermIsSharedNotCountedTwice) {
  // The same sensitivity in both: the weights sum to one, so the fused sensitivity is it again
  // (two estimates do not halve a calibration error they share).
  std::mt19937 rng(11);
  PoseEstimate a = estimate(truthPose(), randomCovariance(&rng, 0.003));
  PoseEstimate b = estimate(truthPose(), randomCovariance(&rng, 0.008));
  Eigen::Matrix<double, 6, 5> S;
  for (int i = 0; i < 30; ++i) S(i) = std::normal_distribution<double>(0, 1)(rng);
  a.calibration_sensitivity = b.calibration_sensitivity = S;
  PoseEstimate f;
  ASSERT_TRUE(fusePoseEstimates(a, b, &f));
  EXPECT_LT((f.calibration_sensitivity - S).norm(), 1e-9 * S.norm());
  // Different sensitivities: each weighted by its estimate's share of the information.
  b.calibration_sensitivity.setZero();
  ASSERT_TRUE(fusePoseEstimates(a, b, &f));
  const Matrix6d w_a = f.own * a.own.inverse();
  EXPECT_LT((f.calibration_sensitivity - w_a * S).norm(), 1e-9 * S.norm());
}

TEST(PoseFusion, RefusesWhatDoesNotFuse) {
  const Matrix6d C = 1e-4 * Matrix6d::Identity();
  PoseEstimate f;
  f.T_21 = SE3Quat();
  Matrix6d singular = C;
  singular(5, 5) = 0;
  EXPECT_FALSE(fusePoseEstimates(estimate(truthPose(), singular), estimate(truthPose(), C), &f));
  Matrix6d nan = C;
  nan(0, 0) = NAN;
  EXPECT_FALSE(fusePoseEstimates(estimate(truthPose(), C), estimate(truthPose(), nan), &f));
  Vector6d apart;
  apart << 0.5, 0, 0, 0, 0, 0;  // 29 degrees: not two estimates of one pose
  EXPECT_FALSE(fusePoseEstimates(estimate(truthPose(), C),
                                 estimate(SE3Quat::exp(apart) * truthPose(), C), &f));
  EXPECT_LT(f.T_21.log().norm(), 1e-15);  // untouched
}

}  // namespace
}  // namespace pnpba
