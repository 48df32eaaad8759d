// The points' elimination and back-substitution kernels, in both of their builds, against the Schur
// complement formed with dense matrices: S = -H_pl (H_ll + lambda I)^-1 H_lp on and below the block
// diagonal, rhs = -H_pl (H_ll + lambda I)^-1 b_l, and D = (H_ll + lambda I)^-1 kept per point.
#include "landmark_elimination.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "pnpba/core/cpu_features.h"

namespace pnpba {
namespace {

TEST(LandmarkElimination, BothBuildsEqualTheDenseSchurComplement) {
  constexpr int kPoses = 3, kPoints = 25;
  constexpr double kLambda = 0.3;
  std::mt19937_64 rng(12);
  std::normal_distribution<double> g;
  std::uniform_int_distribution<int> pose_of(0, kPoses - 1);
  // Each point seen by one to three distinct poses.
  std::vector<LandmarkBlocks> landmarks(kPoints);
  std::vector<AdjacentBlock> adjacency;
  std::vector<double> hll(9 * kPoints), bl(3 * kPoints), hpl;
  Eigen::MatrixXd H_pl = Eigen::MatrixXd::Zero(6 * kPoses, 3 * kPoints);
  Eigen::MatrixXd H_ll = Eigen::MatrixXd::Zero(3 * kPoints, 3 * kPoints);
  Eigen::VectorXd b_l(3 * kPoints);
  for (int l = 0; l < kPoints; ++l) {
    Eigen::Matrix3d M;
    for (int k = 0; k < 9; ++k) M.data()[k] = g(rng);
    const Eigen::Matrix3d V = M * M.transpose() + 0.1 * Eigen::Matrix3d::Identity();
    Eigen::Map<Eigen::Matrix3d>(hll.data() + 9 * l) = V;
    H_ll.block<3, 3>(3 * l, 3 * l) = V;
    for (int k = 0; k < 3; ++k) b_l[3 * l + k] = bl[3 * l + k] = g(rng);
    landmarks[l] = {3, 9 * static_cast<size_t>(l), 3 * static_cast<size_t>(l), adjacency.size(),
                    adjacency.size()};
    std::vector<int> poses;
    for (int k = 0, n = 1 + l % 3; k < n; ++k) {
      const int p = pose_of(rng);
      if (std::find(poses.begin(), poses.end(), p) != poses.end()) continue;
      poses.push_back(p);
      adjacency.push_back({p, hpl.size()});
      for (int c = 0; c < 3; ++c) {
        for (int r = 0; r < 6; ++r) {
          hpl.push_back(g(rng));
          H_pl(6 * p + r, 3 * l + c) = hpl.back();
        }
      }
    }
    landmarks[l].adj_end = adjacency.size();
  }
  const std::vector<int> pose_offset = {0, 6, 12};
  const Eigen::MatrixXd damped =
      H_ll + kLambda * Eigen::MatrixXd::Identity(3 * kPoints, 3 * kPoints);
  const Eigen::MatrixXd D = damped.inverse();
  const Eigen::MatrixXd S_expected = -H_pl * D * H_pl.transpose();
  const Eigen::VectorXd rhs_expected = -H_pl * D * b_l;

  for (int build = 0; build < (cpuHasAvx2Fma() ? 2 : 1); ++build) {
    Eigen::MatrixXd S = Eigen::MatrixXd::Zero(6 * kPoses, 6 * kPoses);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(6 * kPoses);
    std::vector<double> dinv(9 * kPoints, 0.0);
    (build == 0 ? eliminateLandmarks63 : avx2::eliminateLandmarks63)(
        landmarks.data(), landmarks.size(), adjacency.data(), pose_offset.data(), hll.data(),
        bl.data(), hpl.data(), kLambda, dinv.data(), S.data(), static_cast<int>(S.rows()),
        rhs.data());
    for (int bi = 0; bi < kPoses; ++bi) {
      for (int bj = 0; bj <= bi; ++bj) {
        EXPECT_LT((S.block<6, 6>(6 * bi, 6 * bj) - S_expected.block<6, 6>(6 * bi, 6 * bj)).norm(),
                  1e-10 * (1 + S_expected.norm()))
            << "block " << bi << "," << bj << " build " << build;
      }
      for (int bj = bi + 1; bj < kPoses; ++bj) {
        const bool untouched = S.block<6, 6>(6 * bi, 6 * bj).isZero(0);
        EXPECT_TRUE(untouched) << "block " << bi << "," << bj << " above the diagonal written";
      }
    }
    EXPECT_LT((rhs - rhs_expected).norm(), 1e-10 * (1 + rhs_expected.norm())) << "build " << build;
    // The back-substitution from a pose step: xl = D (b_l - H_lp xp).
    Eigen::VectorXd xp(6 * kPoses);
    for (int k = 0; k < xp.size(); ++k) xp[k] = g(rng);
    std::vector<double> xl(3 * kPoints, NAN);
    (build == 0 ? backSubstitute63 : avx2::backSubstitute63)(
        landmarks.data(), landmarks.size(), adjacency.data(), pose_offset.data(), hpl.data(),
        dinv.data(), bl.data(), xp.data(), xl.data());
    const Eigen::VectorXd xl_expected = D * (b_l - H_pl.transpose() * xp);
    EXPECT_LT((Eigen::Map<const Eigen::VectorXd>(xl.data(), xl.size()) - xl_expected).norm(),
              1e-10 * (1 + xl_expected.norm()))
        << "build " << build;
    for (int l = 0; l < kPoints; ++l) {
      EXPECT_LT(
          (Eigen::Map<const Eigen::Matrix3d>(dinv.data() + 9 * l) - D.block<3, 3>(3 * l, 3 * l))
              .norm(),
          1e-10 * (1 + D.block<3, 3>(3 * l, 3 * l).norm()));
    }
  }
}

}  // namespace
}  // namespace pnpba
