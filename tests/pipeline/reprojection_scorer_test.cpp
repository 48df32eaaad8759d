// The RANSAC's pose scorer (pipeline/src/reprojection_scorer.h) against the error written out
// with Eigen's pose and camera: every pair, in front of camera 2 or not, for counts that do and
// do not fill its four-pair steps.
#include "reprojection_scorer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace pnpba {
namespace {

TEST(ReprojectionScorer, EqualsTheProjectedErrorOfEveryPair) {
  PinholeCamera K;
  K.fy = -K.fy;  // rows running upwards, as in ICL-NUIM: the sign must survive the kernel
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (int n : {1, 3, 4, 7, 64, 1501}) {
    Correspondences pairs(n);
    for (Correspondence& c : pairs) {
      // Depths from -1 to 5 m: some points end behind camera 2.
      c.X_1 = Eigen::Vector3d(unit(rng), unit(rng), 2 + 3 * unit(rng));
      c.uv_2 = Eigen::Vector2d(320 + 300 * unit(rng), 240 + 220 * unit(rng));
    }
    const SE3Quat T(
        Eigen::AngleAxisd(0.7 * unit(rng), Eigen::Vector3d(unit(rng), 1, unit(rng)).normalized())
            .toRotationMatrix(),
        Eigen::Vector3d(unit(rng), unit(rng), unit(rng)));
    std::vector<double> e2;
    ReprojectionScorer(pairs, K).squaredErrors(T, &e2);
    ASSERT_EQ(static_cast<int>(e2.size()), n);
    int behind = 0;
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d P = T.rotation().toRotationMatrix() * pairs[i].X_1 + T.translation();
      if (P.z() <= 0) {
        EXPECT_TRUE(std::isinf(e2[i])) << "pair " << i << " of " << n;
        ++behind;
        continue;
      }
      const Eigen::Vector2d uv(K.fx * P.x() / P.z() + K.cx, K.fy * P.y() / P.z() + K.cy);
      const double expected = (uv - pairs[i].uv_2).squaredNorm();
      EXPECT_NEAR(e2[i], expected, 1e-9 * (1 + expected)) << "pair " << i << " of " << n;
    }
    if (n == 1501) {
      EXPECT_GT(behind, 0);  // the behind-the-camera branch was exercised
    }
  }
}

}  // namespace
}  // namespace pnpba
