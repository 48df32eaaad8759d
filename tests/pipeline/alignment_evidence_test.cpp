// The alignment evidence's covariance (alignment_evidence.h) against an independent computation:
// the spread of the poses the RGB-D alignment returns over many draws of the same image noise.
// Independent noise and noise that neighbouring pixels share (same per-pixel sigma) must both be
// read at their size: a covariance from the information alone would report them alike.
#include "pnpba/pipeline/alignment_evidence.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

#include "calibration_error.h"
#include "pnpba/pipeline/rgbd_alignment.h"

namespace pnpba {
namespace {

// A wall 2 m ahead with a smooth pattern: the colour pins the slide along it.
cv::Mat patternedWall() {
  cv::Mat pattern(480, 640, CV_32FC1);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      pattern.at<float>(v, u) =
          static_cast<float>(120 + 60 * std::sin(u / 23.0) * std::cos(v / 31.0));
    }
  }
  return pattern;
}

// Gaussian noise of the given per-pixel sigma, blurred over blur_px first (0: independent).
cv::Mat noise(int seed, double sigma, double blur_px) {
  cv::Mat n(480, 640, CV_32FC1);
  cv::RNG rng(seed);
  rng.fill(n, cv::RNG::NORMAL, 0.0, 1.0);
  if (blur_px > 0) {
    cv::GaussianBlur(n, n, cv::Size(0, 0), blur_px);
    cv::Scalar mean, stddev;
    cv::meanStdDev(n, mean, stddev);
    n *= 1.0 / stddev[0];
  }
  return n * sigma;
}

cv::Mat toImage(const cv::Mat& f) {
  cv::Mat out;
  f.convertTo(out, CV_8UC1);
  return out;
}

struct Spread {
  double measured_x = 0, measured_y = 0;  // variance of the aligned poses' x, y translation
  double residual_x = 0, residual_y = 0;  // mean reported variance of the same: residual part
  double reported_x = 0, reported_y = 0;  // and the whole covariance (with the resolution floor)
  double floor_x = 0, floor_y = 0;        // the resolution floor's sigma of the same (m)
};

// Image 2 is the pattern plus noise, the true pose the identity: the alignment's answers spread
// by the noise alone.
Spread spreadOver(int draws, double sigma, double blur_px) {
  const PinholeCamera k;
  const cv::Mat depth(480, 640, CV_16UC1, cv::Scalar(2 * 5000));
  const cv::Mat pattern = patternedWall();
  const cv::Mat image1 = toImage(pattern);
  Spread s;
  double sum_x = 0, sum_y = 0, sum_xx = 0, sum_yy = 0;
  for (int i = 0; i < draws; ++i) {
    const cv::Mat image2 = toImage(pattern + noise(100 + i, sigma, blur_px));
    const RgbdAlignment a = alignRgbd(image1, depth, image2, depth, k, 5000.0, SE3Quat(), {}, {});
    EXPECT_TRUE(a.ok) << a.failure;
    const Eigen::Vector3d t = a.T_21.translation();
    sum_x += t.x(), sum_y += t.y(), sum_xx += t.x() * t.x(), sum_yy += t.y() * t.y();
    const AlignmentEvidence e = measureAlignment(image1, depth, image2, depth, k, 5000.0, a.T_21);
    EXPECT_TRUE(e.covariance_ok);
    s.residual_x += e.residual_covariance(3, 3) / draws;
    s.residual_y += e.residual_covariance(4, 4) / draws;
    s.reported_x += e.covariance(3, 3) / draws;
    s.reported_y += e.covariance(4, 4) / draws;
    s.floor_x = std::sqrt(e.resolution_covariance(3, 3));
    s.floor_y = std::sqrt(e.resolution_covariance(4, 4));
  }
  s.measured_x = (sum_xx - sum_x * sum_x / draws) / (draws - 1);
  s.measured_y = (sum_yy - sum_y * sum_y / draws) / (draws - 1);
  return s;
}

TEST(AlignmentEvidence, ReportsTheSpreadOfIndependentAndOfSharedNoise) {
  constexpr int kDraws = 24;  // a variance from 24 draws is within a factor 1.6 at 95 %
  const Spread independent = spreadOver(kDraws, 6.0, 0.0);
  const Spread shared = spreadOver(kDraws, 6.0, 3.0);
  // Independent noise: the residuals' part is the spread itself.
  EXPECT_GT(independent.residual_x / independent.measured_x, 0.5);
  EXPECT_LT(independent.residual_x / independent.measured_x, 2.0);
  EXPECT_GT(independent.residual_y / independent.measured_y, 0.5);
  EXPECT_LT(independent.residual_y / independent.measured_y, 2.0);
  // Noise shared over about 3 px, of the same per-pixel sigma: the spread grows 15-20 times. An
  // information-only covariance would not move; the cells' scatter reads four times as much
  // (what a linear model of the correlation predicts at this sampling; the rest is the noise
  // moving the pattern's gradients, which no residual shows), and the resolution floor covers the
  // remainder.
  EXPECT_GT(shared.measured_x, 8 * independent.measured_x);
  EXPECT_GT(shared.residual_x, 3 * independent.residual_x);
  EXPECT_GT(shared.residual_y, 3 * independent.residual_y);
  EXPECT_GT(shared.reported_x, 0.7 * shared.measured_x);
  EXPECT_GT(shared.reported_y, 0.7 * shared.measured_y);
  // The floor is the resolution's image motion at the wall's distance: the depth pins the tilt,
  // so a slide of resolution_px * z / f is all the colour leaves (0.3 px at 2 m, f = 525 px).
  const double slide = AlignmentEvidenceOptions().resolution_px * 2.0 / PinholeCamera().fx;
  EXPECT_NEAR(independent.floor_x, slide, 0.2 * slide);
  EXPECT_NEAR(independent.floor_y, slide, 0.2 * slide);
}

// The depths' and colours' own estimate (dense_step, dense_covariance) leaves the feature pairs
// out: pairs that say another pose change the combined covariance but not it, and its one
// Gauss-Newton step from an off pose lands near the truth the images alone hold.
TEST(AlignmentEvidence, TheDenseEstimateIsTheImagesAloneWhateverTheFeaturePairsSay) {
  const PinholeCamera k;
  const cv::Mat depth(480, 640, CV_16UC1, cv::Scalar(2 * 5000));
  const cv::Mat image = toImage(patternedWall());
  Eigen::Matrix<double, 6, 1> offset;
  offset << 0.0, 0.0, 0.002, 0.004, -0.003, 0.0;  // 0.11 deg about the axis, 5 mm sideways
  const SE3Quat T_off = SE3Quat::exp(offset);
  // Pairs on the wall placed 2 cm off the truth: a feature estimate far from the images' own.
  std::vector<AlignmentFeature> pairs;
  const SE3Quat T_pairs(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.02, 0, 0));
  for (int i = 0; i < 60; ++i) {
    const Eigen::Vector3d X = k.backProject({40.0 + 9.5 * i, 60.0 + 6.0 * i}, 2.0);
    pairs.push_back({X, k.project(T_pairs.map(X)), 1.0});
  }
  const AlignmentEvidence alone = measureAlignment(image, depth, image, depth, k, 5000.0, T_off);
  const AlignmentEvidence with =
      measureAlignment(image, depth, image, depth, k, 5000.0, T_off, pairs);
  ASSERT_TRUE(alone.dense_ok);
  ASSERT_TRUE(with.dense_ok);
  EXPECT_GT(with.feature_samples, 0);
  EXPECT_LT((with.dense_step - alone.dense_step).norm(), 1e-12);
  EXPECT_LT((with.dense_covariance - alone.dense_covariance).norm(),
            1e-9 * alone.dense_covariance.norm());
  EXPECT_GT((with.covariance - alone.covariance).norm(), 1e-3 * alone.covariance.norm());
  // Without pairs the dense estimate's covariance is the evidence's own.
  EXPECT_LT((alone.dense_covariance - alone.covariance).norm(), 1e-9 * alone.covariance.norm());
  // One step from 5 mm off: within a fifth of that of the truth (the identity).
  const Eigen::Matrix<double, 6, 1> left = (SE3Quat::exp(with.dense_step) * T_off).log();
  EXPECT_LT(left.tail<3>().norm(), 0.2 * offset.tail<3>().norm());
  EXPECT_LT(left.head<3>().norm(), 0.2 * offset.head<3>().norm());
}

// A wall 3 m ahead and a floor 0.6 m below camera 1, with a pattern smooth at the pixels' scale,
// seen from camera 1 (T_21 the identity) or camera 2: its grey image and its depth (x5000). A
// Gauss-Newton step of the colour holds over image motions of a few pixels there.
struct PlanesView {
  cv::Mat grey, depth;
};
PlanesView renderPlanes(const PinholeCamera& k, const SE3Quat& T_21) {
  PlanesView view{cv::Mat(480, 640, CV_8UC1), cv::Mat(480, 640, CV_16UC1)};
  const Eigen::Matrix3d R_12 = T_21.rotation().toRotationMatrix().transpose();
  const Eigen::Vector3d centre = -(R_12 * T_21.translation());  // camera 2 in frame 1
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const Eigen::Vector3d ray = R_12 * k.backProject({u, v}, 1.0);
      double s = (3.0 - centre.z()) / ray.z();                         // the wall, z = 3
      if (ray.y() > 0) s = std::min(s, (0.6 - centre.y()) / ray.y());  // the floor, y = 0.6
      const Eigen::Vector3d P = centre + s * ray;
      const double a = P.y() < 0.6 - 1e-9 ? P.y() : P.z();  // the wall's or the floor's own axis
      view.grey.at<uint8_t>(v, u) = cv::saturate_cast<uint8_t>(
          128 + 50 * std::sin(P.x() / 0.06) * std::cos(a / 0.08) + 30 * std::sin(a / 0.11));
      view.depth.at<uint16_t>(v, u) = cv::saturate_cast<uint16_t>(T_21.map(P).z() * 5000);
    }
  }
  return view;
}

// The calibration sensitivity (calibration_sensitivity, dense_calibration_sensitivity) against
// an independent computation: the images re-read through a camera 0.5-1 % or 1 px off, the dense
// estimate's step from the true pose moves by the sensitivity's column times the error. The
// algebra (calibrationResiduals, each residual's derivative by the moved point) is
// checked against residuals resampled from the images.
TEST(AlignmentEvidence, CalibrationSensitivityIsTheDenseEstimatesShiftUnderAMiscalibratedCamera) {
  const PinholeCamera k;
  const SE3Quat T_21(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.15, Eigen::Vector3d(0.3, 1, 0.1).normalized())),
      Eigen::Vector3d(0.25, -0.05, 0.1));
  const PlanesView one = renderPlanes(k, SE3Quat()), two = renderPlanes(k, T_21);
  auto evidence = [&](const PinholeCamera& camera, double depth_scale) {
    return measureAlignment(one.grey, one.depth, two.grey, two.depth, camera, depth_scale, T_21);
  };
  const AlignmentEvidence base = evidence(k, 5000.0);
  ASSERT_TRUE(base.dense_ok && base.covariance_ok);
  // Without feature pairs the two sensitivities are one.
  EXPECT_LT((base.calibration_sensitivity - base.dense_calibration_sensitivity).norm(),
            1e-9 * base.dense_calibration_sensitivity.norm());
  // Errors in the model's units: fx, fy relative, cx, cy in pixels, depths read (1 + e) times;
  // each moves the wall's image by about a pixel.
  const double error[5] = {0.005, 0.005, 1.0, 1.0, 0.01};
  for (int c = 0; c < 5; ++c) {
    const test::OffCalibration calibration = test::offCalibration(k, c, error[c]);
    const AlignmentEvidence off = evidence(calibration.camera, 5000.0 / calibration.depth_factor);
    ASSERT_TRUE(off.dense_ok);
    const Eigen::Matrix<double, 6, 1> moved = off.dense_step - base.dense_step;
    const Eigen::Matrix<double, 6, 1> predicted =
        base.dense_calibration_sensitivity.col(c) * error[c];
    SCOPED_TRACE("parameter " + std::to_string(c) + ": moved " + std::to_string(moved.norm()) +
                 ", predicted " + std::to_string(predicted.norm()));
    // Rotation as the metres it moves the wall 3 m ahead by, against the larger of the two:
    // within 30 % of it (measured 3-18 %: the steps also carry the images' 8-bit rounding).
    const Eigen::Matrix<double, 6, 1> metric =
        (Eigen::Matrix<double, 6, 1>() << 3, 3, 3, 1, 1, 1).finished();
    const double size =
        std::max(moved.cwiseProduct(metric).norm(), predicted.cwiseProduct(metric).norm());
    EXPECT_LT((moved - predicted).cwiseProduct(metric).norm(), 0.3 * size);
    EXPECT_GT(size, 1e-4);  // a tenth of a millimetre or more: a shift, not the steps' noise
  }
}

TEST(AlignmentEvidence, InvalidOptionsAreNamed) {
  EXPECT_EQ(AlignmentEvidenceOptions().validate(), "");
  AlignmentEvidenceOptions o;
  o.cell_px = 0;
  EXPECT_NE(o.validate().find("cell size"), std::string::npos);
  o = {};
  o.resolution_px = 0;  // one resolution without the other would pin a direction exactly
  EXPECT_NE(o.validate().find("resolutions"), std::string::npos);
  o.depth_resolution = 0;  // both off: no floor
  EXPECT_EQ(o.validate(), "");
  o = {};
  o.gate_sigmas = std::nan("");
  EXPECT_NE(o.validate(), "");
}

}  // namespace
}  // namespace pnpba
