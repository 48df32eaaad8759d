// What two RGB-D frames say about a pose T_21, pixel by pixel, apart from any optimiser:
//   geometric   the depth-1 point moved by T_21 against the plane depth 2 sees where it lands
//               (point-to-plane distance, noise k z^2 per point);
//   photometric the intensity of image 1 at the point against image 2 where it lands.
// From the same samples: robust residual scales (1.4826 MAD), the photometric agreement (zero-
// mean normalised cross-correlation of the co-visible intensities) and the pose's covariance.
//
// The covariance has two parts.
// - The residuals' own: neighbouring samples share their errors (smooth depth noise, blur, JPEG
//   blocks, a surface the depth fits badly), so the samples are grouped into square cells of
//   frame 1, taken as independent, and (the cluster-robust "sandwich")
//     C_r = H^-1 (S + H) H^-1,   S = G / (G - 1) sum_cells g_c g_c^T,
//     g_c = sum over the cell's samples of J_i^T r_i / s_i^2,
//   H = sum J_i^T J_i / s_i^2 over the same samples and the feature pairs, G cells. S reads how
//   large and how correlated the errors are where the pose was fitted; H is the floor of
//   independent errors at the robust scales, for residuals that vanish (an exact rendering).
// - The alignment's resolution: its photometric cost is rough below a pixel and its depth term
//   carries the depth noise into the pose (rendered pairs with exact ground truth: the
//   sandwich alone read NEES 200-1100 with no dependence on the cell size from 32 to 128 px;
//   aligned again from the true pose, the alignment returned to the same offset, and without
//   depth noise the offset halved). So the pose is known no better than one sample would pin it
//   with its image motion known to resolution_px and its depth to depth_resolution of the
//   measured depth noise, however many samples there are:
//     C_s = (M_px / resolution_px^2 + M_depth / depth_resolution^2)^-1,
//   M_px the samples' mean J_px^T J_px (J_px: the pixel Jacobian), M_depth their mean depth
//   information at the measured scale. Its shape is the scene's geometry: colour carries the
//   slide along a wall, depth the distance and the tilt.
// covariance = C_r + C_s. Its inverse, the information, shows a direction the scene leaves free
// (a slide along a plane) as small rather than hiding it.
//
// The feature pairs join the alignment, so its pose also rests on what the feature BA reads.
// The depths and colours alone are a second estimate independent of the feature pairs, the one
// to fuse with the feature BA's (pose_fusion.h): from T_21 one Gauss-Newton step of the dense
// samples alone, with their own C_r (dense samples and cells only) + C_s.
//
// Tangent order [w, v] for the left perturbation T <- exp(d) T, as SE3Quat (DESIGN.md 4).
// Pixels are used as pinhole pixels, as in depth_consistency.h.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
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
  // Side of the square cells of frame-1 pixels whose errors may share a cause; cells are
  // independent. Larger is more conservative and noisier (fewer cells).
  int cell_px = 32;
  // The alignment's resolution (header): pixels of image motion, and depth in its measured noise
  // sigmas; both 0: no floor. Calibrated on rendered pairs with exact ground truth over both
  // depth-path scenes (covariance_bench --true-calibration-sigmas): the poor-texture room
  // (Gaussian depth noise) reads mean NEES 1.8 / 3.6 on its two paths, the cabinet (a Kinect-like
  // sensor's quantised disparities) 18.8, median 5.3, 92 % inside; at 0.05 the room read 4.1 / 8.1
  // but the cabinet 36.3, 50 % inside (docs/two_view.md).
  double resolution_px = 0.3;
  double depth_resolution = 0.1;
  double feature_gate_px = 12.0;  // feature pairs within this add their pixel information
  // The frames' brightness change taken out of the photometric residuals as the alignment takes
  // it; set it with RgbdAlignmentOptions::brightness_gain_sigma (> 0: gain and offset; 0, the
  // default: the offset alone).
  double brightness_gain_sigma = 0.0;
  std::string validate() const;  // empty when valid
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
  int cells = 0;  // cells holding samples: the independent groups the covariance rests on
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();  // C^-1
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();   // C_r + C_s
  Eigen::Matrix<double, 6, 6> residual_covariance = Eigen::Matrix<double, 6, 6>::Zero();    // C_r
  Eigen::Matrix<double, 6, 6> resolution_covariance = Eigen::Matrix<double, 6, 6>::Zero();  // C_s
  // The pose shift per unit calibration error of the estimate these samples and feature pairs
  // make together (columns as calibrationSensitivity's: fx, fy relative, cx, cy in pixels of
  // `camera`, the depth scale relative): -H^-1 sum_i J_i^T (D_i m_i) / s_i^2 over the samples and
  // pairs in H, m_i the sample's apparent motion under the error (covariance_model.h), D_i its
  // residual's derivative by the moved point. A colour sample answers only along its image
  // gradient and a depth sample only along its surface normal: a model of pixels and depths
  // that answer in every direction gave rendered pairs' fused poses the wrong direction of
  // shift (docs/two_view.md).
  Eigen::Matrix<double, 6, 5> calibration_sensitivity = Eigen::Matrix<double, 6, 5>::Zero();
  bool covariance_ok = false;  // false when a direction has (numerically) no information
  // The depths and colours alone, without the feature pairs: their estimate exp(dense_step) T_21
  // and its covariance (header). dense_ok false when they leave a direction free.
  Eigen::Matrix<double, 6, 1> dense_step = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 6> dense_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  // Its pose shift per unit calibration error, as calibration_sensitivity of the dense samples
  // alone.
  Eigen::Matrix<double, 6, 5> dense_calibration_sensitivity = Eigen::Matrix<double, 6, 5>::Zero();
  bool dense_ok = false;
};

// image1/image2: 8-bit grey or BGR; depths CV_16UC1 of the images' size.
AlignmentEvidence measureAlignment(const cv::Mat& image1, const cv::Mat& depth1,
                                   const cv::Mat& image2, const cv::Mat& depth2,
                                   const PinholeCamera& camera, double depth_scale,
                                   const SE3Quat& T_21,
                                   const std::vector<AlignmentFeature>& features = {},
                                   const AlignmentEvidenceOptions& options = {});

}  // namespace pnpba
