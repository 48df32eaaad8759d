// The outlier rounds (refinePose, kPose and the rounds of kRgbd) on the dedicated motion-only
// solver, and kRgbd's final graph on the dedicated RGB-D solver (rgbd_pair.h), give what they
// gave on the graph engine: the graph still runs them when its log is asked for, which makes the
// comparison.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "pnpba/pipeline/pose_refinement.h"

namespace pnpba {
namespace {

std::vector<PointPair> randomPairs(unsigned seed, const SE3Quat& truth, const PinholeCamera& k) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1, 1), depth(0.8, 5), chance(0, 1);
  std::normal_distribution<double> pixel(0, 1.0);
  std::vector<PointPair> pairs;
  while (pairs.size() < 120) {
    const Eigen::Vector3d X(2 * unit(rng), 1.5 * unit(rng), depth(rng));
    const Eigen::Vector3d P = truth.map(X);
    if (P.z() < 0.3) continue;
    PointPair p;
    p.X_1 = X;
    p.uv_1 = k.project(X);
    p.uv_2 = k.project(P) + Eigen::Vector2d(pixel(rng), pixel(rng));
    if (chance(rng) < 0.25) p.uv_2 += Eigen::Vector2d(60 * unit(rng), 60 * unit(rng));
    p.sigma_2 = std::pow(1.2, static_cast<int>(4 * chance(rng)));
    // Depth 2 where it agrees, missing, or off by more than its gate (camera 2's edge then
    // carries the pixel alone): the RGB-D graph's three kinds of observation.
    const double kind = chance(rng);
    p.depth_2 = kind < 0.15 ? std::nan("") : kind < 0.25 ? 1.3 * P.z() : P.z();
    pairs.push_back(p);
  }
  return pairs;
}

TEST(PoseRounds, TheDedicatedSolverGivesTheGraphsResults) {
  const PinholeCamera k;
  for (unsigned seed = 1; seed <= 25; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(-1, 1);
    Vector6d xi, off;
    for (int i = 0; i < 6; ++i) xi(i) = (i < 3 ? 0.2 : 0.5) * unit(rng), off(i) = 0.03 * unit(rng);
    const SE3Quat truth = SE3Quat::exp(xi);
    const std::vector<PointPair> pairs = randomPairs(seed, truth, k);
    for (BundleMode mode : {BundleMode::kPose, BundleMode::kRgbd}) {
      RefinementOptions arrays;
      arrays.mode = mode;
      RefinementOptions graph = arrays;
      graph.verbose = true;  // the graph path, whose log this is
      graph.log = [](const std::string&) {};
      const Refinement a = refinePose(pairs, SE3Quat::exp(off) * truth, k, arrays);
      const Refinement g = refinePose(pairs, SE3Quat::exp(off) * truth, k, graph);
      // Four rounds of up to 10 LM steps each stop on a relative decrease of 1e-10: the
      // round-off of one pass (the solver maps points by a rotation matrix, the edges by the
      // quaternion) stays below 1e-8 rad / m (measured: at most 1.4e-9).
      EXPECT_LT((a.T_21 * g.T_21.inverse()).log().norm(), 1e-8) << seed;
      EXPECT_EQ(a.inlier, g.inlier) << seed;
      EXPECT_EQ(a.num_inliers, g.num_inliers);
      EXPECT_EQ(a.iterations, g.iterations) << seed;
      EXPECT_EQ(a.dof, g.dof);
      EXPECT_EQ(a.depth2, g.depth2) << seed;
      EXPECT_EQ(a.solver, g.solver);
      // (kRgbd: of the full graph at the rounds' pose, which carries that round-off.)
      EXPECT_NEAR(a.chi2_initial, g.chi2_initial, 1e-8 * (1 + g.chi2_initial));
      EXPECT_NEAR(a.chi2_final, g.chi2_final, 1e-8 * (1 + g.chi2_final));
      ASSERT_EQ(a.covariance_ok, g.covariance_ok);
      if (g.covariance_ok) {
        EXPECT_LT((a.covariance - g.covariance).norm(), 1e-8 * g.covariance.norm());
      }
    }
  }
}

}  // namespace
}  // namespace pnpba
