// What two RGB-D frames say about a pose T_21, pixel by pixel, apart from any optimiser:
//   geometric   the depth-1 point moved by T_21 against the plane depth 2 sees where it lands
//               (point-to-plane distance, noise k z^2 per point);
//   photometric the intensity of image 1 at the point against image 2 where it lands.
// From the same samples: robust residual scales (1.4826 MAD), the photometric agreement (zero-
// mean normalised cross-correlation of the co-visible intensities) and the pose's information
// matrix (geometric and photometric Jacobians, each term over its robust variance, and the
// feature pairs' pixel Jacobians). Its inverse
// shows a direction the scene leaves free (a slide along a plane) as large rather than hiding
// it behind a fixed inflation.
//
// Tangent order [w, v] for the left perturbation T <- exp(d) T, as SE3Quat (DESIGN.md 4).
// Pixels are used as pinhole pixels, as in depth_consistency.h.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "pnpba/features/pinhole_camera.h"
#include "pnpba/optimize/se3_quat.h"
#include "pnpba/pipeline/rgbd_alignment.h"

namespace pnpba {

struct AlignmentEvidenceOptions {
  int stride = 4;                      // sample every n-th pixel of frame 1
  double depth_noise_k = 0.003;        // depth sigma k z^2 (1/m), as the RGB-D BA's depth residuals
  double depth_noise_floor_m = 0.005;  // plus this (quantisation, calibration)
  // Samples within this many robust sigmas enter the information (occlusion edges do not).
  double gate_sigmas = 3.0;
  // Neighbouring samples share their errors (smooth depth noise, blur, JPEG blocks): the
  // information of N samples is that of about N / this many independent ones.
  double correlated_samples = 16.0;
  // The covariance is this times the inverse information. Calibrated on rendered pairs with
  // exact ground truth (wide-baseline sweep, depth-path poses of the poor-texture room and the
  // Kinect-like cabinet): the squared error was 10-15 times the inverse information's trace.
  double variance_factor = 12.0;
  double feature_gate_px = 12.0;  // feature pairs within this add their pixel information
};

struct AlignmentEvidence {
  int geometric_samples = 0, photometric_samples = 0;  // inside the gate
  int feature_samples = 0;                             // feature pairs within their gate
  int depth1_samples = 0;  // sampled depth-1 pixels with a depth: the overlap's denominator
  // Share of the sampled depth-1 pixels that land on depth 2's surface within the gate: how much
  // of frame 1 the pose explains.
  double overlap() const {
    return depth1_samples > 0 ? static_cast<double>(geometric_samples) / depth1_samples : 0.0;
  }
  double geometric_scale = 0;    // robust sigma of the noise-normalised point-to-plane residual
  double photometric_sigma = 0;  // robust sigma of the intensity residual (0-255 units)
  double photometric_agreement = -1;  // NCC of co-visible intensities (-1: too few samples)
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool covariance_ok = false;  // false when a direction has (numerically) no information
};

// image1/image2: 8-bit grey or BGR; depths CV_16UC1 of the images' size.
AlignmentEvidence measureAlignment(const cv::Mat& image1, const cv::Mat& depth1,
                                   const cv::Mat& image2, const cv::Mat& depth2,
                                   const PinholeCamera& camera, double depth_scale,
                                   const SE3Quat& T_21,
                                   const std::vector<AlignmentFeature>& features = {},
                                   const AlignmentEvidenceOptions& options = {});

}  // namespace pnpba
