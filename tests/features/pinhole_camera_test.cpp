// Keypoint undistortion against the distortion model written out here (OpenCV's 5-coefficient
// model), and the pinhole projection round trip.
#include "pnpba/features/pinhole_camera.h"

#include <gtest/gtest.h>

#include "pnpba/features/correspondences.h"
#include "pnpba/features/depth_lookup.h"

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

// The pairs are built from the matched keypoints with a depth alone; their pixels are those of
// the whole image's keypoints undistorted (each point is undistorted on its own), bit for bit.
TEST(PinholeCamera, CorrespondencesUndistortTheirKeypointsAsTheWholeSetIs) {
  PinholeCamera c;
  c.fx = 517.3, c.fy = 516.5, c.cx = 318.6, c.cy = 255.3;
  c.distortion = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};
  Features f1, f2;
  for (int i = 0; i < 40; ++i) {
    f1.keypoints.emplace_back(20.f + 15.3f * i, 30.f + 11.7f * i, 8.f);
    f2.keypoints.emplace_back(610.f - 14.9f * i, 20.f + 10.9f * i, 8.f);
  }
  cv::Mat depth(480, 640, CV_16UC1, cv::Scalar(10000));  // 2 m at x5000
  depth.rowRange(200, 300).setTo(0);                     // a hole: those matches are dropped
  std::vector<cv::DMatch> matches;
  for (int i = 0; i < 40; i += 3) matches.emplace_back(i, 39 - i, 10.f + i);
  DepthOptions depth_options;
  const Correspondences pairs =
      buildCorrespondences(f1, f2, matches, depth, c, depth_options, /*undistort=*/true);
  const auto all1 = undistortKeypoints(f1.keypoints, c);
  const auto all2 = undistortKeypoints(f2.keypoints, c);
  size_t expected = 0;
  for (const cv::DMatch& m : matches) {
    const cv::Point2f& k = f1.keypoints[m.queryIdx].pt;
    expected += depthAt(depth, k.x, k.y, depth_options).has_value() ? 1 : 0;
  }
  ASSERT_EQ(pairs.size(), expected);
  ASSERT_LT(pairs.size(), matches.size());
  for (const Correspondence& p : pairs) {
    EXPECT_EQ(p.uv_1, all1[p.keypoint_1]);
    EXPECT_EQ(p.uv_2, all2[p.keypoint_2]);
    EXPECT_DOUBLE_EQ(p.depth, 2.0);
    EXPECT_EQ(p.X_1, c.backProject(all1[p.keypoint_1], 2.0));
  }
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
