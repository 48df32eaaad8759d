// The depth consistency: the true pose agrees with both depth images, a wrong one is contradicted,
// and the counts are those of a plain count written from its definition (depth_consistency.h).
#include "pnpba/pipeline/depth_consistency.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "pnpba/pipeline/camera.h"
#include "pnpba/synthetic/synthetic_pair.h"

namespace pnpba {
namespace {

SyntheticPair renderedPair() {
  SyntheticPairOptions o;
  o.seed = 11;
  return renderSyntheticPair(o);  // the sample's room, 3 degrees and 12 cm apart
}

// One direction, as the header defines it: every stride-th pixel of `from` back-projected,
// moved by T, projected into `to` (the nearest pixel), compared with the depth seen there.
void plainCount(const cv::Mat& from, const cv::Mat& to, const SE3Quat& T, const PinholeCamera& k,
                double scale, int stride, double noise_k, DepthConsistency* c) {
  for (int v = stride / 2; v < from.rows; v += stride) {
    for (int u = stride / 2; u < from.cols; u += stride) {
      const int raw = from.at<uint16_t>(v, u);
      if (raw == 0) continue;
      const Eigen::Vector3d X = T.map(k.backProject(Eigen::Vector2d(u, v), raw / scale));
      if (X.z() < 0.1) continue;
      const Eigen::Vector2d uv = k.project(X);
      const long x = std::lround(uv.x()), y = std::lround(uv.y());
      if (x < 0 || y < 0 || x >= to.cols || y >= to.rows) continue;
      const int seen = to.at<uint16_t>(static_cast<int>(y), static_cast<int>(x));
      if (seen == 0) continue;
      ++c->checked;
      const double z = seen / scale;
      const double tolerance = 0.02 + 2.0 * noise_k * z * z;
      if (std::abs(X.z() - z) <= tolerance) {
        ++c->agree;
      } else if (X.z() - z < -tolerance) {
        ++c->contradict;
      }
    }
  }
}

TEST(DepthConsistency, TheTruePoseAgreesAndOneTooFarForwardIsContradicted) {
  const SyntheticPair p = renderedPair();
  const Camera camera;
  const DepthConsistency truth = measureDepthConsistency(p.view1.depth, p.view2.depth, p.T_21,
                                                         camera.pinhole, camera.depth_scale);
  EXPECT_GT(truth.checked, 2000);
  EXPECT_GT(truth.consistency(), 0.95);
  // Camera 2 placed 30 cm further forward than it was: frame 1's points land 30 cm in front of
  // the surfaces depth 2 sees, which camera 2 would have seen instead.
  Vector6d forward = Vector6d::Zero();
  forward(5) = -0.3;
  const DepthConsistency wrong =
      measureDepthConsistency(p.view1.depth, p.view2.depth, SE3Quat::exp(forward) * p.T_21,
                              camera.pinhole, camera.depth_scale);
  EXPECT_LT(wrong.consistency(), 0.5);
  EXPECT_GT(wrong.contradict, truth.contradict + 1000);
}

TEST(DepthConsistency, CountsAreThePlainCountsOfItsDefinition) {
  const SyntheticPair p = renderedPair();
  const Camera camera;
  const int stride = 8;
  const double noise_k = 0.003;
  Vector6d off = Vector6d::Zero();
  off << 0.01, -0.02, 0.005, 0.04, -0.03, 0.08;  // agreement, contradiction and occlusion alike
  for (const SE3Quat& T : {p.T_21, SE3Quat::exp(off) * p.T_21}) {
    DepthConsistency plain;
    plainCount(p.view1.depth, p.view2.depth, T, camera.pinhole, camera.depth_scale, stride, noise_k,
               &plain);
    plainCount(p.view2.depth, p.view1.depth, T.inverse(), camera.pinhole, camera.depth_scale,
               stride, noise_k, &plain);
    const DepthConsistency c = measureDepthConsistency(
        p.view1.depth, p.view2.depth, T, camera.pinhole, camera.depth_scale, stride, noise_k);
    // The measure rounds through a rotation matrix and reciprocals where the plain count
    // divides: a sample exactly on a tolerance or a pixel's edge may fall the other way, none
    // more.
    const int slack = std::max(2, plain.checked / 1000);
    EXPECT_NEAR(c.checked, plain.checked, slack);
    EXPECT_NEAR(c.agree, plain.agree, slack);
    EXPECT_NEAR(c.contradict, plain.contradict, slack);
    EXPECT_GT(plain.agree, 0);
  }
}

// The measure's loop as it was before a row went in two passes (where each sample lands, then
// what is seen there): one sample at a time, the same arithmetic.
void onePassCount(const cv::Mat& from, const cv::Mat& to, const SE3Quat& T, const PinholeCamera& k,
                  double scale, int stride, double noise_k, DepthConsistency* out) {
  const Eigen::Matrix3d R = T.rotation().toRotationMatrix();
  const Eigen::Vector3d t = T.translation();
  const double per_unit = 1.0 / scale;
  for (int v = stride / 2; v < from.rows; v += stride) {
    for (int u = stride / 2; u < from.cols; u += stride) {
      const uint16_t raw = from.at<uint16_t>(v, u);
      if (raw == 0) continue;
      const double z = raw * per_unit;
      const double x_of = (u - k.cx) / k.fx, y_of = (v - k.cy) / k.fy;
      const Eigen::Vector3d X = R * Eigen::Vector3d(x_of * z, y_of * z, z) + t;
      if (X.z() < 0.1) continue;
      const double iz = 1.0 / X.z();
      const long x = std::lround(k.fx * X.x() * iz + k.cx);
      const long y = std::lround(k.fy * X.y() * iz + k.cy);
      if (x < 0 || y < 0 || x >= to.cols || y >= to.rows) continue;
      const uint16_t seen = to.at<uint16_t>(static_cast<int>(y), static_cast<int>(x));
      if (seen == 0) continue;
      ++out->checked;
      const double z_seen = seen * per_unit;
      const double tolerance = 0.02 + 2.0 * noise_k * z_seen * z_seen;
      const double gap = X.z() - z_seen;
      if (std::abs(gap) <= tolerance) {
        ++out->agree;
      } else if (gap < -tolerance) {
        ++out->contradict;
      }
    }
  }
}

// Exactly the one-pass counts, on poses that agree, contradict, look past the frame's edge and
// turn it away, at the strides the pipeline and its tests use.
TEST(DepthConsistency, TwoPassRowsCountAsOneSampleAtATime) {
  const SyntheticPair p = renderedPair();
  const Camera camera;
  std::vector<SE3Quat> poses = {p.T_21, p.T_21.inverse(), SE3Quat()};
  Vector6d step = Vector6d::Zero();
  for (int i = 0; i < 24; ++i) {
    for (int k = 0; k < 6; ++k) step(k) = 0.03 * std::sin(1.7 * i + 2.3 * k) * (k < 3 ? 1 : 4);
    poses.push_back(SE3Quat::exp(step * (1 + i / 6)) * p.T_21);
  }
  for (int stride : {3, 8}) {
    for (const SE3Quat& T : poses) {
      DepthConsistency one;
      onePassCount(p.view1.depth, p.view2.depth, T, camera.pinhole, camera.depth_scale, stride,
                   0.003, &one);
      onePassCount(p.view2.depth, p.view1.depth, T.inverse(), camera.pinhole, camera.depth_scale,
                   stride, 0.003, &one);
      const DepthConsistency two = measureDepthConsistency(
          p.view1.depth, p.view2.depth, T, camera.pinhole, camera.depth_scale, stride, 0.003);
      EXPECT_EQ(two.checked, one.checked);
      EXPECT_EQ(two.agree, one.agree);
      EXPECT_EQ(two.contradict, one.contradict);
    }
  }
}

}  // namespace
}  // namespace pnpba
