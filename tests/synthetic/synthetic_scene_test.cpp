// The renderer's ground truth: a point seen in view 1 at its rendered depth, moved by T_21 and
// projected into view 2, lands where view 2 renders the same depth and colour.
#include "pnpba/synthetic/synthetic_scene.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace pnpba {
namespace {

TEST(SyntheticScene, TwoViewsAgreeWithTheirGroundTruthMotion) {
  const SyntheticScene scene(7);
  const SyntheticCamera camera;
  const DepthNoise exact{0.0, 0.0, 6.0};
  const SE3Quat T_21 = SyntheticScene::defaultMotion();
  const RenderedView v1 = scene.render(camera, SE3Quat(), exact, 1);
  const RenderedView v2 = scene.render(camera, T_21, exact, 2);
  ASSERT_EQ(v1.depth.type(), CV_16UC1);
  ASSERT_EQ(v1.colour.size(), cv::Size(640, 480));
  int checked = 0, agreeing = 0;
  for (int v = 20; v < 460; v += 23) {
    for (int u = 20; u < 620; u += 29) {
      const uint16_t raw = v1.depth.at<uint16_t>(v, u);
      if (raw == 0) continue;
      const Eigen::Vector3d X1 =
          camera.pinhole.backProject(Eigen::Vector2d(u, v), raw / camera.depth_scale);
      const Eigen::Vector3d X2 = T_21.map(X1);
      const Eigen::Vector2d uv2 = camera.pinhole.project(X2);
      const int u2 = static_cast<int>(std::lround(uv2.x())),
                v2p = static_cast<int>(std::lround(uv2.y()));
      if (u2 < 1 || v2p < 1 || u2 >= 639 || v2p >= 479) continue;
      ++checked;
      // Occlusions and depth edges disagree; everything else must agree to quantisation.
      const double z2 = v2.depth.at<uint16_t>(v2p, u2) / camera.depth_scale;
      if (std::abs(z2 - X2.z()) < 0.01 * X2.z()) ++agreeing;
    }
  }
  ASSERT_GT(checked, 200);
  EXPECT_GT(agreeing, 0.9 * checked);
}

TEST(SyntheticScene, DepthScaleAndNoiseSeedAreApplied) {
  const SyntheticScene scene(7);
  SyntheticCamera a, b;
  b.depth_scale = 1000.0;
  const DepthNoise exact{0.0, 0.0, 6.0};
  const RenderedView va = scene.render(a, SE3Quat(), exact, 1);
  const RenderedView vb = scene.render(b, SE3Quat(), exact, 1);
  const double za = va.depth.at<uint16_t>(240, 320) / 5000.0;
  const double zb = vb.depth.at<uint16_t>(240, 320) / 1000.0;
  EXPECT_GT(za, 0.1);
  EXPECT_NEAR(za, zb, 1e-3);
  const RenderedView n1 = scene.render(a, SE3Quat(), DepthNoise{}, 1);
  const RenderedView n2 = scene.render(a, SE3Quat(), DepthNoise{}, 1);
  EXPECT_EQ(cv::norm(n1.depth, n2.depth, cv::NORM_INF), 0.0);  // same seed, same image
}

}  // namespace
}  // namespace pnpba

namespace pnpba {
namespace {

TEST(SyntheticScene, LookAtMotionHasTheRequestedRotationAndTranslation) {
  for (double deg : {0.0, 12.0, 35.0, 60.0}) {
    for (double d : {0.0, 0.3, 1.0, 2.0}) {
      const SE3Quat T = SyntheticScene::lookAtMotion(deg, Eigen::Vector3d(0.2, 1.0, -0.1), d);
      EXPECT_NEAR(Eigen::AngleAxisd(T.rotation()).angle() * 180 / M_PI, deg, 1e-9);
      // Camera 2's centre in camera 1: -R^T t.
      const Eigen::Vector3d centre = -(T.rotation().inverse() * T.translation());
      EXPECT_NEAR(centre.norm(), d, 1e-9) << deg << " " << d;
    }
  }
}

TEST(SyntheticScene, PoorTextureHasFewCornersRichHasMany) {
  SyntheticCamera camera;
  const DepthNoise exact{0.0, 0.0, 8.0};
  auto edgeDensity = [&](SceneTexture texture) {
    const RenderedView v =
        SyntheticScene(3, SceneLayout::kClosedRoom, texture).render(camera, SE3Quat(), exact, 1);
    // Pixels whose 4-neighbourhood spans more than 30 grey levels.
    cv::Mat grey;
    cv::cvtColor(v.colour, grey, cv::COLOR_BGR2GRAY);
    int count = 0;
    for (int y = 1; y < grey.rows - 1; ++y)
      for (int x = 1; x < grey.cols - 1; ++x)
        count += std::abs(grey.at<uint8_t>(y, x + 1) - grey.at<uint8_t>(y, x - 1)) +
                     std::abs(grey.at<uint8_t>(y + 1, x) - grey.at<uint8_t>(y - 1, x)) >
                 30;
    // Every pixel of the closed room has depth: it surrounds the camera.
    EXPECT_EQ(cv::countNonZero(v.depth), v.depth.rows * v.depth.cols);
    return count;
  };
  EXPECT_GT(edgeDensity(SceneTexture::kRich), 10 * edgeDensity(SceneTexture::kPoor));
}

}  // namespace
}  // namespace pnpba
