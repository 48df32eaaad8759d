// Direct RGB-D alignment of two frames from a seed pose: the pose that makes image 2 look like
// image 1 where depth 1 puts its pixels (photometric residuals), puts those points on the
// surface depth 2 sees (point-to-plane residuals), and reprojects the feature pairs that exist
// (pixel residuals), all in one robust Gauss-Newton over a four-level image pyramid. Colour
// constrains what depth alone leaves sliding (a cabinet's planes, a floor and a wall); depth and
// features keep the colour term from drifting where the images are flat.
//
// Working in image space ties the pose to the colour images: depth 1 only places the pixels,
// so a depth image a little out of step with its colour image moves the structure, not the
// pose (on TUM fr3_cabinet, aligning the depth clouds to each other instead drifted 3.4 deg /
// 6.8 cm from the ground truth when started on it; this drifted 1 deg / 1.2 cm).
//
// T_21 maps camera-1 points onto camera-2 points; tangent order [w, v], left perturbation
// T <- exp(d) T (DESIGN.md 3-4). Deterministic; no threads.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pnpba/features/pinhole_camera.h"
#include "pnpba/optimize/se3_quat.h"

namespace pnpba {

struct RgbdAlignmentOptions {
  int levels = 4;  // image pyramid levels, solved coarse to fine (80x60 to 640x480)
  // The finest level solved (0: full resolution). Stopping at 1 and then solving level 0 alone
  // (levels = 1) from where it stopped gives exactly the one alignment over every level.
  int finest_level = 0;
  int iterations = 12;  // Gauss-Newton iterations per level, at most
  // A level ends when a step turns less than this (rad) and moves less than this (m): 0.03 deg
  // and 0.5 mm. Near the end the steps shrink by about a third each, and at full resolution they
  // stall at 2-5e-4 on real texture-poor frames (the robust scales and the surfaces under the
  // samples change from step to step): at 3e-4, 8 of fr3_cabinet's 52 full-resolution levels ran
  // to the 12-iteration cap moving a fraction of a millimetre back and forth, at 1.5-3 ms an
  // iteration. At 5e-4 its full-resolution iterations fell from 266 to about 170; the 3-seed
  // sweep, fr3_cabinet and its wide pairs gave 3 more poses within 2 deg / 5 cm, 0 wrong either
  // way (docs/benchmarks.md). 1e-4 before 3e-4 ran 3-5 iterations more still.
  double converged_step = 5e-4;
  // At full resolution a level also ends, from its third step on, at a step within this many of
  // the pose's own standard deviations (sqrt(d^T H d), H the step's normal equations with the
  // correlated samples' share): there the steps stop shrinking and wander about the minimum, each
  // about as large as the pose's uncertainty (the rendered cabinet's: 0.9-1.7 sigmas each from
  // the third step to the 12-step cap, 1.3-1.7 ms each). At 1.5 the sweep's, fr3_cabinet's and
  // fr1_desk's answers were unchanged and the rendered cabinet's alignment stage 22-27 % shorter
  // (docs/benchmarks.md). 0: off (converged_step alone).
  double settled_step_sigmas = 1.5;
  int finest_stride = 4;         // sample every n-th pixel at full resolution (halved per level)
  double huber_sigmas = 1.345;   // Huber width in robust sigmas (95 % efficiency)
  double depth_noise_k = 0.003;  // depth sigma k z^2 + floor (as the RGB-D BA)
  double depth_noise_floor_m = 0.005;
  // Neighbouring pixels share their errors (smooth depth noise, blur, JPEG blocks): the
  // information of N dense samples is taken as that of N / this many independent ones when they
  // are weighed against the feature pairs (the covariance measures it: alignment_evidence.h).
  double correlated_samples = 16.0;
  double feature_gate_px = 12.0;  // feature pairs beyond this at a level's start are left out
  // > 0: frame 2's brightness is fitted as (1 + gain) times frame 1's plus an offset at every
  // iteration, the gain with this prior 1-sigma (brightness_change.h); 0: the offset alone. For
  // a camera whose auto exposure changes between frames: through a gain of 1.3 the rendered
  // cabinet's depth path returned 48 poses within 2 deg / 5 cm of 108 at 0.25, 30 with the offset
  // alone (51 at gain 1), 0 wrong either way; but on the real fr3_cabinet key frames 0.25 returned
  // 51 of 54 and 26 of 45 wide pairs against 52 and 30 (docs/two_view.md), hence off by default.
  double brightness_gain_sigma = 0.0;
  std::string validate() const;  // empty when valid
};

// A feature pair: the depth-1 point and where image 2 saw it (undistorted pixels).
struct AlignmentFeature {
  Eigen::Vector3d X_1;
  Eigen::Vector2d uv_2;
  double sigma_px = 1.0;
};

struct RgbdAlignment {
  bool ok = false;
  std::string failure;
  SE3Quat T_21;
  int iterations = 0;
  int feature_inliers = 0;  // features within the gate at the end
  double time_ms = 0;
  // Stopped at its deadline, between two steps (the depth path's time budget): not ok.
  bool out_of_time = false;
};

// image1/image2: 8-bit grey or BGR; depths CV_16UC1 of the images' size; `camera` gives
// undistorted pixels for the features (the dense terms use the images' pixels as pinhole
// pixels). Throws Error for invalid options; ok = false when too little overlaps.
RgbdAlignment alignRgbd(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                        const cv::Mat& depth2, const PinholeCamera& camera, double depth_scale,
                        const SE3Quat& T_seed, const std::vector<AlignmentFeature>& features,
                        const RgbdAlignmentOptions& options);

}  // namespace pnpba
