// Keypoint undistortion against the distortion model written out here (OpenCV's 5-coefficient
// model), and the pinhole projection round trip.
#include "pnpba/features/pinhole_camera.h"

#include <gtest/gtest.h>

#include "pnpba/features/correspondences.h"

namespace pnpba {
namespace {

// Distorted pixel of normalised undistorted coordinates (x, y).
Eigen::Vector2d distort(const PinholeCamera& c, double x, double y) {
  const auto& d = c.distortion;  // k1 k2 p1 p2 k3
  const double r2 = x * x + y * y;
  const double radial = 1 + d[0] * r2 + d[1] * r2 * r2 + d[4] * r2 * r2 * r2;
  const double xd = x * radial + 2 * d[2] * x * y + d[3] * (r2 + 2 * x * x);
  const double yd = y * radial + d[2] * (r2 + 2 * y * y) + 2 * d[3] * x * y;
  return {c.fx * xd + c.cx, c.fy * yd + c.cy};
}

TEST(PinholeCamera, UndistortKeypointsInvertsTheDistortionModel) {
  PinholeCamera c;
  c.fx = 517.3, c.fy = 516.5, c.cx = 318.6, c.cy = 255.3;
  c.distortion = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};  // TUM freiburg1
  std::vector<cv::KeyPoint> keypoints;
  std::vector<Eigen::Vector2d> ideal;
  for (double x = -0.5; x <= 0.5; x += 0.25) {
    for (double y = -0.4; y <= 0.4; y += 0.2) {
      const Eigen::Vector2d raw = distort(c, x, y);
      keypoints.emplace_back(static_cast<float>(raw.x()), static_cast<float>(raw.y()), 8.f);
      ideal.push_back(c.project(Eigen::Vector3d(x, y, 1)));
    }
  }
  const auto undistorted = undistortKeypoints(keypoints, c);
  ASSERT_EQ(undistorted.size(), ideal.size());
  for (size_t i = 0; i < ideal.size(); ++i) {
    // The keypoints are floats: 1e-3 px of storage error, a little more after iteration.
    EXPECT_LT((undistorted[i] - ideal[i]).norm(), 0.02) << i;
  }
}

TEST(PinholeCamera, NoDistortionLeavesKeypointsUnchanged) {
  const PinholeCamera c;
  ASSERT_FALSE(c.hasDistortion());
  const std::vector<cv::KeyPoint> k{{12.25f, 300.5f, 8.f}, {600.f, 7.75f, 8.f}};
  const auto u = undistortKeypoints(k, c);
  EXPECT_DOUBLE_EQ(u[0].x(), 12.25);
  EXPECT_DOUBLE_EQ(u[1].y(), 7.75);
}

TEST(PinholeCamera, BackProjectInvertsProject) {
  PinholeCamera c;
  c.fy = -480.0;  // y-flipped cameras exist (ICL-NUIM)
  const Eigen::Vector3d P(0.3, -0.2, 2.5);
  EXPECT_LT((c.backProject(c.project(P), P.z()) - P).norm(), 1e-12);
  PinholeCamera bad;
  bad.fx = std::nan("");
  EXPECT_NE(bad.validate(), "");
}

}  // namespace
}  // namespace pnpba
