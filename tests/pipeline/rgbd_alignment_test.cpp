// The direct RGB-D alignment and the evidence behind the depth path: residual Jacobians against
// central differences, convergence on a rendered texture-poor pair through a Kinect-like sensor,
// and a covariance that shows the direction a plane leaves free.
#include "pnpba/pipeline/rgbd_alignment.h"

#include <gtest/gtest.h>
#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/parallel_for.h>

#include <chrono>
#include <cstring>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <random>

#include "pnpba/core/error.h"
#include "pnpba/pipeline/alignment_evidence.h"
#include "pnpba/synthetic/synthetic_pair.h"
#include "rgbd_residuals.h"

namespace pnpba {
namespace {

double rotationErrorDeg(const SE3Quat& a, const SE3Quat& b) {
  return Eigen::AngleAxisd((a * b.inverse()).rotation()).angle() * 180.0 / M_PI;
}

SyntheticPair cabinetPair(double deg, double metres, unsigned seed) {
  SyntheticPairOptions o;
  o.seed = seed;
  o.layout = SceneLayout::kCabinet;
  o.texture = SceneTexture::kPoor;
  o.sensor = SensorEffects::kinectLike();
  o.noise.noise_k = 0.0025;
  o.T_21 = SyntheticScene::lookAtMotion(deg, Eigen::Vector3d(0.1, 1.0, 0.05), metres);
  return renderSyntheticPair(o);
}

// exp(d) T_21: a seed off the truth by d = [w, v].
SE3Quat offBy(const SyntheticPair& p, double w1, double w2, double w3, double v1, double v2,
              double v3) {
  return SE3Quat::exp((Eigen::Matrix<double, 6, 1>() << w1, w2, w3, v1, v2, v3).finished()) *
         p.T_21;
}

// The pair's four-level pyramid through the default pinhole.
std::vector<RgbdLevel> pyramidOf(const SyntheticPair& p) {
  return rgbdPyramid(p.view1.colour, p.view1.depth, p.view2.colour, p.view2.depth, PinholeCamera{},
                     5000.0, 4);
}

// Depth 2's surfaces are what a per-pixel float image would hold, in an optimised build as in a
// debug one: every coordinate of the point and the normal a float, the normal of unit length
// (to float precision) and facing the camera. GCC 12's vectoriser had dropped the float round
// trip of the normal's and the point's x and y.
TEST(RgbdResiduals, DepthSurfacesHoldFloats) {
  const SyntheticPair p = cabinetPair(15.0, 0.4, 3);
  const std::vector<RgbdLevel> levels = pyramidOf(p);
  auto isFloat = [](double v) {
    volatile float f = static_cast<float>(v);
    return static_cast<double>(f) == v;
  };
  for (int level : {0, 1}) {
    int surfaces = 0;
    for (int y = 0; y < levels[level].depth2.rows; y += 3) {
      for (int x = 0; x < levels[level].depth2.cols; x += 3) {
        Eigen::Vector3d P, n;
        if (!depthSurfaceAt(levels[level], x, y, &P, &n)) continue;
        ++surfaces;
        for (int i = 0; i < 3; ++i) {
          ASSERT_TRUE(isFloat(P[i]) && isFloat(n[i]))
              << "level " << level << " at " << x << ", " << y << ", coordinate " << i;
        }
        ASSERT_NEAR(n.norm(), 1.0, 1e-6);
        ASSERT_LT(n.dot(P), 0.0);
      }
    }
    EXPECT_GT(surfaces, 1000) << "level " << level;
  }
}

TEST(RgbdResiduals, JacobiansMatchCentralDifferences) {
  const SyntheticPair p = cabinetPair(15.0, 0.4, 3);
  const PinholeCamera camera;
  // Pyramid level 1 (smooth enough for differences) at a pose near the truth.
  const std::vector<RgbdLevel> levels =
      rgbdPyramid(p.view1.colour, p.view1.depth, p.view2.colour, p.view2.depth, camera, 5000.0, 2);
  const SE3Quat T =
      SE3Quat::exp(
          (Eigen::Matrix<double, 6, 1>() << 0.004, -0.003, 0.002, 0.01, -0.02, 0.015).finished()) *
      p.T_21;
  DenseResidualOptions o;
  o.stride = 7;
  const DenseResiduals at = denseResiduals(levels[1], T, o);
  ASSERT_GT(at.geometric.size(), 200u);
  // Differences of the same samples: perturbations small enough not to change which pixel of
  // depth 2 a point lands on are rare near edges, so compare medians of the relative error.
  const double h = 1e-6;
  std::vector<double> geometric_error, photometric_error;
  for (int k = 0; k < 6; ++k) {
    Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
    d(k) = h;
    const DenseResiduals plus = denseResiduals(levels[1], SE3Quat::exp(d) * T, o);
    const DenseResiduals minus = denseResiduals(levels[1], SE3Quat::exp(-d) * T, o);
    ASSERT_EQ(plus.geometric.size(), at.geometric.size());
    ASSERT_EQ(minus.geometric.size(), at.geometric.size());
    for (size_t i = 0; i < at.geometric.size(); ++i) {
      const double g = (plus.geometric[i].value - minus.geometric[i].value) / (2 * h);
      geometric_error.push_back(std::abs(g - at.geometric[i].J(k)) / std::max(1.0, std::abs(g)));
      const double f = (plus.photometric[i].value - minus.photometric[i].value) / (2 * h);
      photometric_error.push_back(std::abs(f - at.photometric[i].J(k)) /
                                  std::max(1.0, std::abs(f)));
    }
  }
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  // The geometric residual is exact in the point (the plane is held); the photometric one
  // uses the Sobel gradient for the bilinear image's slope, which agree to a few per cent.
  EXPECT_LT(median(geometric_error), 1e-4);
  EXPECT_LT(median(photometric_error), 0.1);
}

// The residuals' Jacobians are written out entry by entry (for speed); they must be the matrix
// products they stand for, bit for bit, so that no alignment moves: random points, normals,
// gradients and scales, with zeros among them (a zero product's sign is part of the bits).
TEST(RgbdResiduals, WrittenOutJacobiansMatchTheProducts) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  const PinholeCamera k;
  int compared = 0;
  for (int i = 0; i < 20000; ++i) {
    Eigen::Vector3d n(normal(rng), normal(rng), normal(rng));
    n.normalize();
    if (i % 7 == 0) n(i % 3) = 0.0;
    if (i % 11 == 0) n(0) = -0.0;
    Eigen::Vector3d X(normal(rng), normal(rng), 0.3 + 4.0 * std::abs(normal(rng)));
    if (i % 13 == 0) X(1) = 0.0;
    const double inv_sigma = 1.0 / (0.005 + std::abs(normal(rng)));
    double g0 = 40.0 * normal(rng), g1 = 40.0 * normal(rng);
    if (i % 5 == 0) g1 = 0.0;
    const double iz = 1.0 / X.z();
    const Eigen::Matrix<double, 1, 6> plane = planeJacobian(n, X, inv_sigma);
    const Eigen::Matrix<double, 1, 6> plane_product =
        n.transpose() * internal::pointByPoseTangent(X) * inv_sigma;
    const Eigen::Matrix<double, 1, 6> photometric = photometricJacobian(k, g0, g1, X, iz);
    const Eigen::Matrix<double, 1, 6> photometric_product =
        Eigen::RowVector2d(g0, g1) * projectionJacobian(k, X, iz);
    for (int j = 0; j < 6; ++j) {
      ASSERT_EQ(std::memcmp(&plane(j), &plane_product(j), sizeof(double)), 0)
          << "plane, sample " << i << ", entry " << j;
      ASSERT_EQ(std::memcmp(&photometric(j), &photometric_product(j), sizeof(double)), 0)
          << "photometric, sample " << i << ", entry " << j;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 120000);
}

// A tilted plane seen by both frames from the same place, frame 1's copy 1 cm nearer: every
// residual's normal (the translation part of its Jacobian) is the plane's, and its value the
// 1 cm along that normal over the depth sigma, computed here from the plane alone.
TEST(RgbdResiduals, APlaneGivesItsNormalAndDistance) {
  const PinholeCamera camera;
  const Eigen::Vector3d normal = Eigen::Vector3d(0.3, -0.2, -1.0).normalized();  // faces camera
  const double offset = 2.0;  // plane n . X = -offset * n.z(): passes (0, 0, 2)
  auto depthOfPlane = [&](double shift) {
    cv::Mat depth(480, 640, CV_16U);
    for (int v = 0; v < depth.rows; ++v) {
      for (int u = 0; u < depth.cols; ++u) {
        const Eigen::Vector3d ray = camera.backProject(Eigen::Vector2d(u, v), 1.0);
        const double z = (offset * normal.z() + shift) / normal.dot(ray);
        depth.at<uint16_t>(v, u) = static_cast<uint16_t>(std::lround(z * 5000.0));
      }
    }
    return depth;
  };
  // Frame 1's plane moved 1 cm along the normal (towards the camera).
  const cv::Mat grey(480, 640, CV_8UC1, cv::Scalar(128));
  const std::vector<RgbdLevel> levels =
      rgbdPyramid(grey, depthOfPlane(0.01), grey, depthOfPlane(0.0), camera, 5000.0, 1);
  DenseResidualOptions o;
  o.stride = 5;
  const DenseResiduals r = denseResiduals(levels[0], SE3Quat(), o);
  ASSERT_GT(r.geometric.size(), 5000u);
  int checked = 0;
  for (const DenseResidual& g : r.geometric) {
    const Eigen::Vector3d n = g.J.tail<3>().transpose();
    // sigma = floor + k z^2 scales both value and Jacobian: their ratio is the distance.
    EXPECT_NEAR(n.normalized().dot(normal), 1.0, 2e-3);
    EXPECT_NEAR(g.value / n.norm(), 0.01, 1e-3);
    ++checked;
  }
  EXPECT_EQ(checked, static_cast<int>(r.geometric.size()));
}

// The residuals are computed in row bands on every core and joined in order: the same bits on
// one thread as on two.
TEST(RgbdResiduals, TheSameOnOneThreadAsOnTwo) {
  const SyntheticPair p = cabinetPair(20.0, 0.3, 5);
  const std::vector<RgbdLevel> levels = rgbdPyramid(p.view1.colour, p.view1.depth, p.view2.colour,
                                                    p.view2.depth, PinholeCamera{}, 5000.0, 1);
  DenseResidualOptions o;
  o.stride = 2;
  auto residualsOn = [&](int threads) {
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    return denseResiduals(levels[0], p.T_21, o);
  };
  const DenseResiduals one = residualsOn(1);
  const DenseResiduals two = residualsOn(2);
  ASSERT_GT(one.geometric.size(), 1000u);
  ASSERT_EQ(one.geometric.size(), two.geometric.size());
  ASSERT_EQ(one.photometric.size(), two.photometric.size());
  EXPECT_EQ(one.depth1_samples, two.depth1_samples);
  EXPECT_EQ(one.intensity2, two.intensity2);
  for (size_t i = 0; i < one.geometric.size(); ++i) {
    ASSERT_EQ(one.geometric[i].value, two.geometric[i].value) << i;
    ASSERT_EQ(one.geometric[i].J, two.geometric[i].J) << i;
    ASSERT_EQ(one.photometric[i].value, two.photometric[i].value) << i;
  }
}

// Depth 2's surfaces as the level keeps them are the ones computed from its depths, to the bit:
// filled from two threads at once, looked up again, and after the level's buffers were rebuilt
// for another pair (a copy of a level keeps nothing, so it computes every surface afresh).
TEST(RgbdResiduals, KeptSurfacesAreTheComputedOnes) {
  const SyntheticPair first = cabinetPair(10.0, 0.2, 1);
  const SyntheticPair second = cabinetPair(20.0, 0.3, 2);
  const PinholeCamera camera;
  std::vector<RgbdLevel> levels;
  auto expectKeptEqualComputed = [&](const char* when) {
    for (int level : {0, 1, 3}) {
      const RgbdLevel& kept = levels[level];
      const RgbdLevel fresh = kept;  // computes every surface from the depths
      const int rows = kept.depth2.rows, cols = kept.depth2.cols;
      int surfaces = 0;
      for (int pass = 0; pass < 2; ++pass) {  // the first pass fills, the second reads
        std::vector<int> found(rows, 0);
        tbb::parallel_for(0, rows, [&](int y) {
          for (int x = 0; x < cols; ++x) {
            Eigen::Vector3d P, n, P_fresh, n_fresh;
            const bool ok = depthSurfaceAt(kept, x, y, &P, &n);
            ASSERT_EQ(ok, depthSurfaceAt(fresh, x, y, &P_fresh, &n_fresh)) << x << ", " << y;
            if (!ok) continue;
            ASSERT_EQ(P, P_fresh) << when << ", level " << level << " at " << x << ", " << y;
            ASSERT_EQ(n, n_fresh) << when << ", level " << level << " at " << x << ", " << y;
            ++found[y];
          }
        });
        surfaces = std::accumulate(found.begin(), found.end(), 0);
      }
      EXPECT_GT(surfaces, rows * cols / 4) << when << ", level " << level;
    }
  };
  rgbdPyramidInto(first.view1.colour, first.view1.depth, first.view2.colour, first.view2.depth,
                  camera, 5000.0, 4, &levels);
  expectKeptEqualComputed("first pair");
  rgbdPyramidInto(second.view1.colour, second.view1.depth, second.view2.colour, second.view2.depth,
                  camera, 5000.0, 4, &levels);
  expectKeptEqualComputed("second pair, the same buffers");
}

// A pyramid built into the buffers an earlier pair's left on this thread is the pyramid built
// afresh, to the bit, and reuses those buffers (the point of recycling them); a pair of another
// size gets buffers of its own size; level 0's gradients come when first needed.
TEST(RgbdPyramid, RecycledBuffersGiveTheSamePyramid) {
  const SyntheticPair first = cabinetPair(10.0, 0.2, 1);
  const SyntheticPair second = cabinetPair(20.0, 0.3, 2);
  const PinholeCamera camera;
  const uchar* reused = nullptr;
  {
    RecycledPyramid earlier;
    rgbdPyramidInto(first.view1.colour, first.view1.depth, first.view2.colour, first.view2.depth,
                    camera, 5000.0, 4, &earlier.levels);
    reused = earlier.levels[0].grey2.data;
  }
  auto expectSame = [](const std::vector<RgbdLevel>& a, const std::vector<RgbdLevel>& b) {
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
      for (auto m : {&RgbdLevel::grey1, &RgbdLevel::grey2, &RgbdLevel::gx2, &RgbdLevel::gy2,
                     &RgbdLevel::depth1, &RgbdLevel::depth2}) {
        ASSERT_EQ((a[i].*m).size(), (b[i].*m).size()) << "level " << i;
        EXPECT_EQ(cv::norm(a[i].*m, b[i].*m, cv::NORM_INF), 0.0) << "level " << i;
      }
      EXPECT_EQ(a[i].x_of, b[i].x_of);
      EXPECT_EQ(a[i].y_of, b[i].y_of);
      EXPECT_EQ(a[i].camera.fx, b[i].camera.fx);
    }
  };
  {
    RecycledPyramid recycled;
    rgbdPyramidInto(second.view1.colour, second.view1.depth, second.view2.colour,
                    second.view2.depth, camera, 5000.0, 4, &recycled.levels);
    EXPECT_EQ(recycled.levels[0].grey2.data, reused);
    // Level 0's gradients wait for the first full-resolution use: none yet, and the residuals
    // refuse the level rather than read the last pair's.
    EXPECT_FALSE(recycled.levels[0].gradients_ready);
    EXPECT_TRUE(recycled.levels[1].gradients_ready);
    EXPECT_THROW(denseResiduals(recycled.levels[0], second.T_21, DenseResidualOptions{}), Error);
    prepareFullResolution(&recycled.levels);
    expectSame(recycled.levels,
               rgbdPyramid(second.view1.colour, second.view1.depth, second.view2.colour,
                           second.view2.depth, camera, 5000.0, 4));
  }
  cv::Mat half_colour1, half_colour2, half_depth1, half_depth2;
  cv::resize(second.view1.colour, half_colour1, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
  cv::resize(second.view2.colour, half_colour2, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
  cv::resize(second.view1.depth, half_depth1, cv::Size(), 0.5, 0.5, cv::INTER_NEAREST);
  cv::resize(second.view2.depth, half_depth2, cv::Size(), 0.5, 0.5, cv::INTER_NEAREST);
  RecycledPyramid smaller;
  rgbdPyramidInto(half_colour1, half_depth1, half_colour2, half_depth2, camera, 5000.0, 4,
                  &smaller.levels);
  prepareFullResolution(&smaller.levels);
  expectSame(smaller.levels,
             rgbdPyramid(half_colour1, half_depth1, half_colour2, half_depth2, camera, 5000.0, 4));
}

TEST(RgbdAlignment, ConvergesOnATexturePoorPairFromAnOffSeed) {
  for (unsigned seed : {1u, 2u}) {
    const SyntheticPair p = cabinetPair(25.0, 0.5, seed);
    // Off by 3 degrees and 10 cm: where a depth registration of a plane-dominated scene lands.
    const SE3Quat off =
        SE3Quat::exp(
            (Eigen::Matrix<double, 6, 1>() << 0.03, -0.035, 0.02, 0.06, -0.05, 0.06).finished()) *
        p.T_21;
    const RgbdAlignment a = alignRgbd(p.view1.colour, p.view1.depth, p.view2.colour, p.view2.depth,
                                      PinholeCamera{}, 5000.0, off, {}, RgbdAlignmentOptions{});
    ASSERT_TRUE(a.ok) << a.failure;
    EXPECT_LT(rotationErrorDeg(a.T_21, p.T_21), 0.5) << "seed " << seed;
    EXPECT_LT((a.T_21.translation() - p.T_21.translation()).norm(), 0.02) << "seed " << seed;
  }
}

// An auto exposure between the frames: frame 2's colour 1.3 or 0.8 times frame 1's (saturating).
// Started at the true pose, the alignment that fits the gain with the offset ends where it ends
// on the unchanged frames (measured: 0.1-0.9 cm, 0.01-0.2 deg apart); with the offset alone the
// intensities' spread reads as image motion, and on these texture-poor frames it slides the pose
// along the cabinet (0.3-12.4 cm, up to 1.2 deg).
TEST(RgbdAlignment, AnExposureChangeDoesNotMoveThePose) {
  RgbdAlignmentOptions with_gain, offset_only;
  with_gain.brightness_gain_sigma = 0.25;
  offset_only.brightness_gain_sigma = 0;
  int slid_offset_only = 0;
  for (unsigned seed : {1u, 2u, 3u, 4u}) {
    const SyntheticPair p = cabinetPair(25.0, 0.5, seed);
    const std::vector<RgbdLevel> unchanged = pyramidOf(p);
    const RgbdAlignment same = alignRgbdPyramid(unchanged, PinholeCamera{}, p.T_21, {}, with_gain);
    ASSERT_TRUE(same.ok) << same.failure;
    for (double gain : {1.3, 0.8}) {
      cv::Mat exposed;
      p.view2.colour.convertTo(exposed, -1, gain);
      const std::vector<RgbdLevel> pyramid = rgbdPyramid(p.view1.colour, p.view1.depth, exposed,
                                                         p.view2.depth, PinholeCamera{}, 5000.0, 4);
      const RgbdAlignment fitted =
          alignRgbdPyramid(pyramid, PinholeCamera{}, p.T_21, {}, with_gain);
      const RgbdAlignment offset =
          alignRgbdPyramid(pyramid, PinholeCamera{}, p.T_21, {}, offset_only);
      ASSERT_TRUE(fitted.ok && offset.ok);
      EXPECT_LT((fitted.T_21.translation() - same.T_21.translation()).norm(), 0.01)
          << "seed " << seed << ", gain " << gain;
      EXPECT_LT(rotationErrorDeg(fitted.T_21, same.T_21), 0.25)
          << "seed " << seed << ", gain " << gain;
      slid_offset_only += (offset.T_21.translation() - same.T_21.translation()).norm() > 0.02;
    }
  }
  // The offset alone slid 4 of the 8 by 2.7-12.4 cm: what the gain takes out.
  EXPECT_GE(slid_offset_only, 3);
}

TEST(RgbdAlignment, FeaturePairsJoinTheRefinement) {
  // With the dense terms nearly switched off, the feature pairs alone carry the pose.
  const SyntheticPair p = cabinetPair(20.0, 0.3, 5);
  std::vector<AlignmentFeature> features;
  const PinholeCamera k;
  for (double x : {-1.0, 0.0, 1.0}) {
    for (double y : {-0.5, 0.3}) {
      for (double z : {2.0, 3.0}) {
        const Eigen::Vector3d X(x, y, z);
        features.push_back({X, k.project(p.T_21.map(X)), 1.0});
      }
    }
  }
  RgbdAlignmentOptions o;
  o.correlated_samples = 1e9;
  const SE3Quat off =
      SE3Quat::exp(
          (Eigen::Matrix<double, 6, 1>() << 0.01, 0.01, -0.01, 0.02, 0.02, -0.02).finished()) *
      p.T_21;
  const RgbdAlignment a = alignRgbd(p.view1.colour, p.view1.depth, p.view2.colour, p.view2.depth, k,
                                    5000.0, off, features, o);
  ASSERT_TRUE(a.ok) << a.failure;
  EXPECT_EQ(a.feature_inliers, static_cast<int>(features.size()));
  EXPECT_LT(rotationErrorDeg(a.T_21, p.T_21), 0.01);
  EXPECT_LT((a.T_21.translation() - p.T_21.translation()).norm(), 1e-3);
}

// Each iteration's normal equations are summed on both cores (photometric and geometric apart,
// each over the row bands in order): the same pose, to the bit, on one thread as on two.
TEST(RgbdAlignment, TheSameOnOneThreadAsOnTwo) {
  const SyntheticPair p = cabinetPair(25.0, 0.5, 2);
  const SE3Quat off = offBy(p, 0.02, -0.02, 0.01, 0.05, -0.03, 0.04);
  const PinholeCamera k;
  const std::vector<RgbdLevel> pyramid = pyramidOf(p);
  auto alignOn = [&](int threads) {
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    return alignRgbdPyramid(pyramid, k, off, {}, RgbdAlignmentOptions{});
  };
  const RgbdAlignment one = alignOn(1);
  const RgbdAlignment two = alignOn(2);
  ASSERT_TRUE(one.ok && two.ok);
  EXPECT_GT(one.iterations, 4);
  EXPECT_EQ(one.iterations, two.iterations);
  EXPECT_EQ(one.T_21.to_homogeneous_matrix(), two.T_21.to_homogeneous_matrix());
  EXPECT_LT(rotationErrorDeg(one.T_21, p.T_21), 0.5);
}

// Under a time budget an alignment stops at the budget's deadline between two steps: past it, it
// takes no step and is not ok (out_of_time); with a deadline far ahead it is the alignment
// without one, to the bit.
TEST(RgbdAlignment, AnAlignmentStopsAtItsDeadline) {
  const SyntheticPair p = cabinetPair(25.0, 0.5, 2);
  const SE3Quat off = offBy(p, 0.02, -0.02, 0.01, 0.05, -0.03, 0.04);
  const PinholeCamera k;
  const std::vector<RgbdLevel> pyramid = pyramidOf(p);
  using Clock = std::chrono::steady_clock;
  const RgbdAlignment free = alignRgbdPyramid(pyramid, k, off, {}, RgbdAlignmentOptions{});
  ASSERT_TRUE(free.ok);
  EXPECT_FALSE(free.out_of_time);
  ASSERT_GT(free.iterations, 4);

  const RgbdAlignment late =
      alignRgbdPyramid(pyramid, k, off, {}, RgbdAlignmentOptions{}, Clock::now());
  EXPECT_FALSE(late.ok);
  EXPECT_TRUE(late.out_of_time);
  EXPECT_EQ(late.iterations, 0);
  EXPECT_NE(late.failure.find("ran out of time"), std::string::npos) << late.failure;

  const RgbdAlignment roomy = alignRgbdPyramid(pyramid, k, off, {}, RgbdAlignmentOptions{},
                                               Clock::now() + std::chrono::hours(1));
  ASSERT_TRUE(roomy.ok);
  EXPECT_FALSE(roomy.out_of_time);
  EXPECT_EQ(roomy.iterations, free.iterations);
  EXPECT_EQ(roomy.T_21.to_homogeneous_matrix(), free.T_21.to_homogeneous_matrix());
}

// The depth path's cross-check stops at half resolution and, when that does not settle the
// pair, solves full resolution alone from there: exactly the one alignment over every level.
TEST(RgbdAlignment, StoppingAtHalfResolutionThenFinishingIsTheOneAlignment) {
  const SyntheticPair p = cabinetPair(25.0, 0.5, 1);
  const SE3Quat off = offBy(p, 0.01, -0.01, 0.005, 0.02, -0.01, 0.02);
  const PinholeCamera k;
  const std::vector<RgbdLevel> pyramid = pyramidOf(p);
  RgbdAlignmentOptions o;
  const RgbdAlignment whole = alignRgbdPyramid(pyramid, k, off, {}, o);
  o.finest_level = 1;
  const RgbdAlignment coarse = alignRgbdPyramid(pyramid, k, off, {}, o);
  o.finest_level = 0;
  o.levels = 1;
  const RgbdAlignment fine = alignRgbdPyramid(pyramid, k, coarse.T_21, {}, o);
  ASSERT_TRUE(whole.ok && coarse.ok && fine.ok);
  EXPECT_GT(fine.iterations, 0);  // level 0 did work: the coarse pose is not the final one
  EXPECT_EQ(coarse.iterations + fine.iterations, whole.iterations);
  EXPECT_EQ(fine.T_21.to_homogeneous_matrix(), whole.T_21.to_homogeneous_matrix());
  EXPECT_NE(coarse.T_21.to_homogeneous_matrix(), whole.T_21.to_homogeneous_matrix());
}

// At full resolution the steps stop shrinking and wander about the minimum, each about as large
// as the pose's own uncertainty: ended at the first step within 1.5 of its sigmas, the level
// saves iterations and lands where running on to the cap or the step bound lands, within a
// fraction of the error both keep to the truth.
TEST(RgbdAlignment, FullResolutionEndsOnceItsStepsAreWithinThePosesUncertainty) {
  const PinholeCamera k;
  int saved = 0;
  for (unsigned seed : {1u, 2u, 3u}) {
    const SyntheticPair p = cabinetPair(25.0, 0.5, seed);
    const std::vector<RgbdLevel> pyramid = pyramidOf(p);
    const SE3Quat off = offBy(p, 0.02, -0.02, 0.01, 0.05, -0.03, 0.04);
    RgbdAlignmentOptions settled, unsettled;
    unsettled.settled_step_sigmas = 0;
    const RgbdAlignment a = alignRgbdPyramid(pyramid, k, off, {}, settled);
    const RgbdAlignment b = alignRgbdPyramid(pyramid, k, off, {}, unsettled);
    ASSERT_TRUE(a.ok && b.ok);
    EXPECT_LE(a.iterations, b.iterations) << "seed " << seed;
    saved += b.iterations - a.iterations;
    // Measured: 0-6 iterations fewer, at most 0.14 deg / 4.2 mm from the longer run's pose,
    // whose errors to the truth were 0.1-0.42 deg / 6-19 mm (the shorter run's 0.1-0.30 deg /
    // 6-16 mm).
    EXPECT_LT(rotationErrorDeg(a.T_21, b.T_21), 0.25) << "seed " << seed;
    EXPECT_LT((a.T_21.translation() - b.T_21.translation()).norm(), 0.01) << "seed " << seed;
    EXPECT_LT(rotationErrorDeg(a.T_21, p.T_21), 0.5) << "seed " << seed;
    EXPECT_LT((a.T_21.translation() - p.T_21.translation()).norm(), 0.02) << "seed " << seed;
  }
  EXPECT_GT(saved, 0);
}

TEST(RgbdAlignment, InvalidOptionsAreNamed) {
  RgbdAlignmentOptions o;
  o.levels = 0;
  EXPECT_NE(o.validate().find("levels"), std::string::npos);
  o = {};
  o.correlated_samples = 0;
  EXPECT_FALSE(o.validate().empty());
  o = {};
  o.finest_level = o.levels;
  EXPECT_NE(o.validate().find("finest level"), std::string::npos);
  o = {};
  o.settled_step_sigmas = -1;
  EXPECT_NE(o.validate().find("settled step"), std::string::npos);
}

// Every sample reads the four images at one pixel: images of different sizes are an error, not
// a read past one image's end.
TEST(RgbdAlignment, ImagesOfDifferentSizesAreAnError) {
  const cv::Mat grey(480, 640, CV_8UC1, cv::Scalar(128));
  const cv::Mat depth(480, 640, CV_16UC1, cv::Scalar(10000));
  const cv::Mat small_depth(240, 320, CV_16UC1, cv::Scalar(10000));
  const PinholeCamera camera;
  try {
    alignRgbd(grey, depth, grey, small_depth, camera, 5000.0, SE3Quat(), {},
              RgbdAlignmentOptions{});
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("640x480 and 320x240"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(
      alignRgbd(grey, depth, grey, depth, camera, 5000.0, SE3Quat(), {}, RgbdAlignmentOptions{}));
}

// A wall seen head-on, one flat colour: depth fixes the distance and two rotations; nothing
// fixes the slide along the wall or the turn about its normal.
TEST(AlignmentEvidence, APlainWallLeavesItsSlideFreeAndTextureFixesIt) {
  const PinholeCamera k;
  cv::Mat depth(480, 640, CV_16UC1, cv::Scalar(2 * 5000));
  cv::Mat plain(480, 640, CV_8UC3, cv::Scalar(120, 120, 120));
  const AlignmentEvidence flat = measureAlignment(plain, depth, plain, depth, k, 5000.0, SE3Quat());
  const bool slides =
      !flat.covariance_ok || flat.covariance(3, 3) > 1.0 || flat.covariance(4, 4) > 1.0;
  EXPECT_TRUE(slides) << "x, y translation variances " << flat.covariance(3, 3) << " "
                      << flat.covariance(4, 4);
  // The same wall with a smooth pattern: the colour now pins the slide, and the reported
  // variance along the wall is small.
  cv::Mat pattern(480, 640, CV_8UC3);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const double s = 120 + 60 * std::sin(u / 23.0) * std::cos(v / 31.0);
      pattern.at<cv::Vec3b>(v, u) = cv::Vec3b::all(cv::saturate_cast<uchar>(s));
    }
  }
  const AlignmentEvidence textured =
      measureAlignment(pattern, depth, pattern, depth, k, 5000.0, SE3Quat());
  ASSERT_TRUE(textured.covariance_ok);
  EXPECT_LT(std::sqrt(textured.covariance(3, 3)), 0.01);
  EXPECT_LT(std::sqrt(textured.covariance(4, 4)), 0.01);
  // Depth pins the distance in both cases.
  EXPECT_LT(std::sqrt(textured.covariance(5, 5)), 0.01);
  EXPECT_GT(textured.photometric_agreement, 0.99);
}

}  // namespace
}  // namespace pnpba
