// The renderer's ground truth: a point seen in view 1 at its rendered depth, moved by T_21 and
// projected into view 2, lands where view 2 renders the same depth and colour.
#include "pnpba/synthetic/synthetic_scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "pnpba/synthetic/synthetic_pair.h"

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

// Colour over the pixel (SyntheticCamera::colour_samples): with 2 x 2 rays each pixel is the
// mean of four centre-sampled renders whose principal point is moved by a quarter pixel each
// way; the depth stays the centre's.
TEST(SyntheticScene, ColourSamplesAverageTheRaysInsideEachPixel) {
  const SyntheticScene scene(7);
  SyntheticCamera camera;
  camera.width = 160, camera.height = 120;
  const SE3Quat T = SyntheticScene::defaultMotion();
  const DepthNoise noise;
  SyntheticCamera averaged = camera;
  averaged.colour_samples = 2;
  const RenderedView box = scene.render(averaged, T, noise, 3);
  const RenderedView centre = scene.render(camera, T, noise, 3);
  cv::Mat sum = cv::Mat::zeros(box.colour.size(), CV_64FC3);
  for (double du : {-0.25, 0.25}) {
    for (double dv : {-0.25, 0.25}) {
      SyntheticCamera shifted = camera;
      shifted.pinhole.cx -= du;
      shifted.pinhole.cy -= dv;
      cv::Mat c;
      scene.render(shifted, T, noise, 3).colour.convertTo(c, CV_64FC3);
      sum += c;
    }
  }
  cv::Mat expected;
  cv::Mat(sum / 4.0).convertTo(expected, CV_8UC3);
  cv::Mat difference;
  cv::absdiff(box.colour, expected, difference);
  // Equal but for rays that fall on a texel boundary (the centre renders take float rays).
  EXPECT_GE(cv::countNonZero(difference.reshape(1) <= 1), 0.999 * difference.total() * 3);
  EXPECT_EQ(cv::norm(box.depth, centre.depth, cv::NORM_INF), 0.0);
  // And it is not the centre's colour: a rich texture changes under the box.
  EXPECT_GT(cv::norm(box.colour, centre.colour, cv::NORM_L1), 0.0);
  SyntheticPairOptions o;
  o.camera.colour_samples = 9;
  EXPECT_NE(o.validate().find("colour samples"), std::string::npos);
  o.camera.colour_samples = 2;
  o.camera.pinhole.distortion = {0.1, 0, 0, 0, 0};
  EXPECT_NE(o.validate().find("distortion"), std::string::npos);
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

// kTiled repeats each surface's texture every 0.5 m: a camera moved 0.5 m along the open room's
// back wall and floor (both textured along x) sees the same colours where it looks at them; the
// rich texture does not repeat there.
TEST(SyntheticScene, TiledTextureRepeatsEveryHalfMetre) {
  const SyntheticCamera camera;
  const DepthNoise exact{0.0, 0.0, 8.0};
  const SE3Quat moved(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-0.5, 0, 0));
  auto medianDifference = [&](SceneTexture texture) {
    const SyntheticScene scene(5, SceneLayout::kOpenRoom, texture);
    cv::Mat a, b, difference;
    cv::cvtColor(scene.render(camera, SE3Quat(), exact, 1).colour, a, cv::COLOR_BGR2GRAY);
    cv::cvtColor(scene.render(camera, moved, exact, 1).colour, b, cv::COLOR_BGR2GRAY);
    // The image's middle: the back wall, 4.5 m away, left and right walls outside it.
    const cv::Rect middle(220, 60, 200, 160);
    cv::absdiff(a(middle), b(middle), difference);
    std::vector<uint8_t> values(difference.begin<uint8_t>(), difference.end<uint8_t>());
    std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
    return static_cast<int>(values[values.size() / 2]);
  };
  EXPECT_LE(medianDifference(SceneTexture::kTiled), 2);
  EXPECT_GE(medianDifference(SceneTexture::kRich), 10);
}

}  // namespace
}  // namespace pnpba

namespace pnpba {
namespace {

// The free cabinet seen from its far side (camera 1 turned half round it) looks as it does from
// the near side but for its handles: the same depth to 5 mm wherever both views have one, except
// on the handles, which stand 2 cm proud of the near side's face (orbit_bench's alias).
TEST(SyntheticScene, FreeCabinetLooksTheSameFromItsFarSideButForItsHandles) {
  const SyntheticScene scene(11, SceneLayout::kFreeCabinet, SceneTexture::kPoor);
  const SyntheticCamera camera;
  const DepthNoise exact{0.0, 0.0, 8.0};
  const RenderedView near_side = scene.render(camera, SE3Quat(), exact, 1);
  const RenderedView far_side = scene.render(camera, SyntheticScene::orbitMotion(180), exact, 2);
  int both = 0, differ = 0;
  cv::Rect handles;
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const int a = near_side.depth.at<uint16_t>(v, u), b = far_side.depth.at<uint16_t>(v, u);
      if (a == 0 || b == 0) continue;
      ++both;
      if (std::abs(a - b) <= 0.005 * camera.depth_scale) continue;
      ++differ;
      handles = differ == 1 ? cv::Rect(u, v, 1, 1) : (handles | cv::Rect(u, v, 1, 1));
    }
  }
  EXPECT_GT(both, 100000);  // the floor within 8 m and the cabinet: 40 % of the image
  // Three 24 x 4 cm handles 2.58 m away: about 3 x 48 x 8 pixels, at the image's centre column.
  EXPECT_GT(differ, 500);
  EXPECT_LT(differ, 3000);
  EXPECT_GE(handles.x, 290);
  EXPECT_LE(handles.x + handles.width, 360);
  EXPECT_GE(handles.y, 280);
  EXPECT_LE(handles.y + handles.height, 420);
}

// The zig-zag repeats every two panels (1.2 m along x): a camera moved by one period sees the
// same depth wherever the structure's ends stay out of both views, one moved by half a period
// (the folds swapped) does not.
TEST(SyntheticScene, StructureRepeatsEveryTwoPanels) {
  const SyntheticScene scene(5, SceneLayout::kStructure, SceneTexture::kPoor);
  const SyntheticCamera camera;
  const DepthNoise exact{0.0, 0.0, 8.0};
  const RenderedView here = scene.render(camera, SE3Quat(), exact, 1);
  auto same_depth_share = [&](double shift_m) {
    // Camera moved by shift_m along x: T_cw maps world x to x - shift.
    const RenderedView moved = scene.render(
        camera, SE3Quat(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-shift_m, 0, 0)), exact, 2);
    int structure = 0, same = 0;
    // The columns that see the middle of the structure from both places (its ends 2.4 m out).
    for (int v = 0; v < 480; ++v) {
      for (int u = 200; u < 440; ++u) {
        const int a = here.depth.at<uint16_t>(v, u), b = moved.depth.at<uint16_t>(v, u);
        // The panels stand 2.6-3.1 m away; the floor in front of them is nearer.
        if (a < 2.62 * camera.depth_scale || b == 0) continue;
        ++structure;
        same += std::abs(a - b) <= 0.005 * camera.depth_scale;
      }
    }
    EXPECT_GT(structure, 20000) << shift_m;
    return static_cast<double>(same) / structure;
  };
  EXPECT_GT(same_depth_share(1.2), 0.99);
  EXPECT_GT(same_depth_share(-1.2), 0.99);
  EXPECT_LT(same_depth_share(0.6), 0.2);
}

// The plain corridor: camera 1 slid 0.6 m along the wall sees the same depth and the same colour
// at every pixel (the floor and the wall run on past the view); moved 0.3 m towards the wall it
// does not.
TEST(SyntheticScene, CorridorLooksTheSameSlidAlongTheWall) {
  const SyntheticScene scene(5, SceneLayout::kCorridor, SceneTexture::kPoor);
  const SyntheticCamera camera;
  const DepthNoise exact{0.0, 0.0, 8.0};
  const RenderedView here = scene.render(camera, SE3Quat(), exact, 1);
  auto same_share = [&](const Eigen::Vector3d& move) {
    const RenderedView moved =
        scene.render(camera, SE3Quat(Eigen::Quaterniond::Identity(), -move), exact, 1);
    int seen = 0, same = 0;
    for (int v = 0; v < 480; ++v) {
      for (int u = 0; u < 640; ++u) {
        const int a = here.depth.at<uint16_t>(v, u), b = moved.depth.at<uint16_t>(v, u);
        if (a == 0) continue;
        ++seen;
        const cv::Vec3b ca = here.colour.at<cv::Vec3b>(v, u), cb = moved.colour.at<cv::Vec3b>(v, u);
        same +=
            std::abs(a - b) <= 0.005 * camera.depth_scale && cv::norm(ca, cb, cv::NORM_INF) <= 8;
      }
    }
    EXPECT_GT(seen, 200000);
    return static_cast<double>(same) / seen;
  };
  EXPECT_GT(same_share(Eigen::Vector3d(0.6, 0, 0)), 0.98);
  EXPECT_GT(same_share(Eigen::Vector3d(-0.6, 0, 0)), 0.98);
  EXPECT_LT(same_share(Eigen::Vector3d(0, 0, 0.3)), 0.5);
}

// The poster scene is one plane: every depth camera 1 sees lies 3 m ahead, and only the poster
// in its middle has corners; the wall around it is plain.
TEST(SyntheticScene, PosterIsOnePlaneWithCornersOnlyOnThePoster) {
  const SyntheticScene scene(5, SceneLayout::kPoster, SceneTexture::kRich);
  const SyntheticCamera camera;
  const DepthNoise exact{0.0, 0.0, 8.0};
  const RenderedView v = scene.render(camera, SE3Quat(), exact, 1);
  int seen = 0, on_plane = 0;
  for (int y = 0; y < v.depth.rows; ++y) {
    for (int x = 0; x < v.depth.cols; ++x) {
      const int d = v.depth.at<uint16_t>(y, x);
      if (d == 0) continue;
      ++seen;
      on_plane += std::abs(d / camera.depth_scale - 3.0) <= 0.002;
    }
  }
  EXPECT_EQ(seen, v.depth.rows * v.depth.cols);
  EXPECT_EQ(on_plane, seen);
  // Seen from 3 m further back, the poster (3.41 m square) fills the middle of the view.
  const RenderedView far = scene.render(
      camera, SE3Quat(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 3)), exact, 1);
  cv::Mat grey;
  cv::cvtColor(far.colour, grey, cv::COLOR_BGR2GRAY);
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(grey, corners, 2000, 0.01, 3);
  ASSERT_GT(corners.size(), 300u);
  const double half_px = 0.5 * 1023.0 / 300.0 / 6.0 * camera.pinhole.fx;  // at 6 m
  for (const cv::Point2f& c : corners) {
    EXPECT_LE(std::abs(c.x - camera.pinhole.cx), half_px + 3) << c;
    EXPECT_LE(std::abs(c.y - camera.pinhole.cy), half_px + 3) << c;
  }
}

// Camera 2 circles the cabinet: the cabinet's centre stays where camera 1 sees it, and camera 2
// stays as far from it.
TEST(SyntheticScene, OrbitMotionCirclesTheFreeCabinet) {
  const Eigen::Vector3d centre(0.0, 0.5, 2.95);  // the cabinet's, in camera 1
  EXPECT_LT(
      (SyntheticScene::orbitMotion(0).to_homogeneous_matrix() - Eigen::Matrix4d::Identity()).norm(),
      1e-12);
  for (double degrees : {30.0, 90.0, 180.0, -45.0}) {
    const SE3Quat T_21 = SyntheticScene::orbitMotion(degrees);
    EXPECT_LT((T_21.map(centre) - centre).norm(), 1e-12) << degrees;
    const Eigen::Vector3d camera2 = T_21.inverse().map(Eigen::Vector3d::Zero());
    EXPECT_NEAR((camera2 - centre).norm(), centre.norm(), 1e-12) << degrees;
    EXPECT_NEAR(camera2.y(), 0.0, 1e-12) << degrees;  // at camera 1's height
    const double turned = Eigen::AngleAxisd(T_21.rotation()).angle() * 180.0 / M_PI;
    EXPECT_NEAR(turned, std::abs(degrees), 1e-9) << degrees;
  }
}

// Kinect-like effects: depth in disparity steps, holes along depth edges, depth moved against
// colour, JPEG colour; the clean render stays untouched without them.
TEST(SensorEffects, QuantiseDepthDropEdgesShiftDepthAndCompressColour) {
  SyntheticPairOptions clean;
  clean.layout = SceneLayout::kCabinet;
  clean.texture = SceneTexture::kPoor;
  clean.noise = {0.0, 0.0, 8.0};
  SyntheticPairOptions kinect = clean;
  kinect.sensor = SensorEffects::kinectLike();
  const SyntheticPair a = renderSyntheticPair(clean);
  const SyntheticPair b = renderSyntheticPair(kinect);
  const SensorEffects e = SensorEffects::kinectLike();
  int depths = 0, on_steps = 0, holes_a = 0, holes_b = 0;
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      holes_a += a.view1.depth.at<uint16_t>(v, u) == 0;
      const uint16_t d = b.view1.depth.at<uint16_t>(v, u);
      if (d == 0) {
        ++holes_b;
        continue;
      }
      ++depths;
      // z = f b s / n for an integer n: the stored value sits on a disparity step.
      const double steps = e.disparity_fb * e.disparity_subpixel / (d / 5000.0);
      on_steps += std::abs(steps - std::round(steps)) < 0.02 * steps / (d / 5000.0) + 0.01;
    }
  }
  EXPECT_GT(depths, 200000);
  EXPECT_GT(on_steps, 0.98 * depths);
  EXPECT_GT(holes_b, holes_a + 1000);  // edges dropped (and the shifted border)
  // The depth moved by (2, 1) px: the clean depth at (u, v) is the shifted one at (u+2, v+1)
  // up to the quantisation step (about 1 % at these depths).
  int compared = 0, matching = 0;
  for (int v = 50; v < 430; v += 7) {
    for (int u = 50; u < 590; u += 7) {
      const double z0 = a.view1.depth.at<uint16_t>(v, u) / 5000.0;
      const double z1 = b.view1.depth.at<uint16_t>(v + 1, u + 2) / 5000.0;
      if (z0 <= 0 || z1 <= 0) continue;
      ++compared;
      matching += std::abs(z0 - z1) < 0.015 * z0 * z0 + 0.001;
    }
  }
  EXPECT_GT(matching, 0.95 * compared);
  // JPEG: close to the clean colour, not equal to it.
  cv::Mat diff;
  cv::absdiff(a.view1.colour, b.view1.colour, diff);
  const cv::Scalar mean_diff = cv::mean(diff);
  EXPECT_GT(mean_diff[0] + mean_diff[1] + mean_diff[2], 0.0);
  EXPECT_LT(mean_diff[0], 3.0);
  SensorEffects bad;
  bad.jpeg_quality = 101;
  EXPECT_FALSE(bad.validate().empty());
}

// A moving object (addObject, withObjectMoved): view 2 of the moved scene differs from the
// static scene's only where the box was or now is, and the box's own points move by exactly its
// motion (a point of its face, moved, is rendered at the moved depth).
TEST(SyntheticScene, AMovedObjectMovesItsOwnPixelsAndNoOthers) {
  SyntheticScene scene(7, SceneLayout::kClosedRoom, SceneTexture::kPoor);
  const Eigen::Vector3d low(-0.3, -0.4, 1.5), size(0.6, 1.7, 0.3);
  const int id = scene.addObject(low, size, 11);
  const SE3Quat motion(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.4, 0, 0));
  const SyntheticScene moved = scene.withObjectMoved(id, motion);
  SyntheticCamera camera;
  const DepthNoise exact{0.0, 0.0, 8.0};
  const RenderedView before = scene.render(camera, SE3Quat(), exact, 1);
  const RenderedView after = moved.render(camera, SE3Quat(), exact, 1);
  // Pixel columns the box's front face covers before (x in [-0.3, 0.3] at z = 1.5) and after
  // ([0.1, 0.7]); every other column renders the same.
  const auto column = [&camera](double x) {
    return camera.pinhole.fx * x / 1.5 + camera.pinhole.cx;
  };
  int changed_outside = 0, changed_inside = 0;
  for (int v = 0; v < 480; v += 4) {
    for (int u = 0; u < 640; u += 4) {
      const bool differs = before.depth.at<uint16_t>(v, u) != after.depth.at<uint16_t>(v, u);
      const bool swept = u > column(-0.3) - 2 && u < column(0.7) + 2;
      (swept ? changed_inside : changed_outside) += differs;
    }
  }
  EXPECT_EQ(changed_outside, 0);
  EXPECT_GT(changed_inside, 500);
  // The face's centre, moved with the box, is where the moved scene renders it, at its depth.
  const Eigen::Vector3d face_centre(0.0, 0.4, 1.5);
  const Eigen::Vector2d uv = camera.pinhole.project(motion.map(face_centre));
  const double z = after.depth.at<uint16_t>(static_cast<int>(std::lround(uv.y())),
                                            static_cast<int>(std::lround(uv.x()))) /
                   camera.depth_scale;
  EXPECT_NEAR(z, 1.5, 1e-3);
  EXPECT_THROW(scene.withObjectMoved(id + 1, motion), std::out_of_range);
}

}  // namespace
}  // namespace pnpba
