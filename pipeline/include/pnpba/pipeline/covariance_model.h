// The covariance the two-view pose reports: what an estimator's information says, scaled by how
// well the model fitted, plus what no fit can see, the calibration's own uncertainty.
//
//   C = v * C_information(s2, s2_depth) + C_calibration + C_motion [+ C_slide]
//
//   C_information   the inverse information at the nominal noise (BA: pixel sigma and depth
//                   noise k z^2; depth path: its robust residual scales); for the RGB-D BA with
//                   the pixel noise variance scaled by s2 and the depth noise variance by
//                   s2_depth (rgbdPoseCovariances), s2 times it for the others
//   s2              the posterior variance factor of the BA's fit (robustVarianceFactor: of
//                   every pair's image-2 residual, outliers and the outlier rounds' cut
//                   accounted for), within [min, max]: 1 when the nominal noise is right, more
//                   when the residuals say it is larger (blur, rolling shutter,
//                   depth-colour misregistration), less when they say it is smaller
//   s2_depth        the same of the inliers' depth-2 residuals (pairDepthChi2, 1 dof): the
//                   depth noise as measured, which the pixel residuals barely show (depth 1
//                   moves a point along camera 1's ray, nearly along camera 2's at small motion)
//   v               the inflation for features that share their errors: the correlation of
//                   nearby features' residuals (correlationInflation; 1 where they are
//                   independent) times the mean size of the groups of inliers that coincide in
//                   both images (duplicateInflation: one corner found at several pyramid levels
//                   reads one depth pixel and carries one localisation error)
//   C_calibration   sum over the calibration parameters p (fx, fy, cx, cy, depth scale) of
//                   sigma_p^2 g_p g_p', g_p the pose shift a unit error of p causes
//   C_motion        per rotation and translation axis, motion_sigma times the angle or the
//                   distance, levelling off at motion_cap_deg / motion_cap_m: what real sensors
//                   add and no residual shows (depth-colour timing and rolling shutter, in
//                   proportion to the motion; depth bias and the ground truth's own error, a
//                   floor a wider baseline does not grow)
//   C_slide         depth-path poses only: per camera-2 translation axis, how loosely the
//                   depth consistency pins a slide (slideSigmas), which no pixel's residual
//                   shows along a plain surface; a floor under C_information's variance along
//                   that axis (slideVarianceAbove), not added to it
//
// A `both` pose (the feature BA and the depth path's alignment agree) is the two estimates fused
// (pose_fusion.h): their own parts, v C_information and the dense estimate's, combined as
// independent (C_slide stays with the depth path's own pose: in a fused one the feature pairs
// pin the slide); the calibration term from the fused sensitivity (both see the same
// calibration); C_motion once.
//
// Why the calibration term has this shape: an error in fx, fy, cx, cy or the depth scale makes
// every camera-frame point appear as A X, one linear map A, in both frames (docs/two_view.md).
// The data then fit A T A^-1, not T; g_p is the least-squares pose shift that explains the
// apparent motion R dA X - dA (T X) of the points under the estimator's own weights (pixel
// sigma, depth noise). It grows with the motion: a 1 % focal error costs nothing at rest and
// centimetres over a metre. Rendered pairs with a 1 % focal or depth-scale error gave mean NEES
// 40-1900 without it (docs/two_view.md, "How honest the covariance is").
//
// Tangent order [w, v] for the left perturbation T <- exp(d) T, as SE3Quat (DESIGN.md 4).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "pnpba/features/pinhole_camera.h"
#include "pnpba/optimize/se3_quat.h"
#include "pnpba/pipeline/pose_graph.h"

namespace pnpba {

struct CovarianceModelOptions {
  // Scale the information's pixel and depth noise by the fit's variance factors (the BA's; the
  // depth path's information is already in its measured residual scales). Bounded: below `min`
  // a small sample's luck would shrink the covariance; above `max` the failure rule's chi2 limit
  // refuses. Rendered pairs fit at 0.11-0.23 (pixels, their noise well below 1 px) and 0.25
  // (depths: the renderer's 0.0015 z^2), twice the depth noise at 1.0; TUM fr1_desk at
  // 0.25-0.7 and 1.1-4.3. A floor of 1 left the rendered feature poses' mean NEES at 0.6-1.9
  // (target 4-9). The failure rule does not read below 1 (TwoViewResult::judged_covariance): a
  // small residual shrinks what a pose graph is told, never what decides a refusal.
  bool scale_by_fit = true;
  double min_variance_factor = 0.1;
  double max_variance_factor = 16.0;
  // Inflate by the residuals' measured correlation between features in one cell of this size.
  bool correlation_inflation = true;
  double correlation_cell_px = 40.0;
  // Inliers within this many pixels of each other in both images count as one feature
  // (duplicateInflation; 0: off). ORB finds most corners at two or more of its pyramid levels:
  // 60-80 % of the rendered pairs' inliers have such a twin, which reads the same depth pixel,
  // so without this the BA's information counts their shared depth error two or three times
  // (covariance_bench told the true calibration: feature groups' mean NEES 10.6-11.5, 6.8-7.2
  // with it).
  double duplicate_radius_px = 3.0;
  // 1-sigma of the calibration the estimate is given (0: trusted exactly). The colour camera's
  // fx, fy, cx, cy: a checkerboard calibration (a focal length to 0.2-0.6 %). The depth scale:
  // a checkerboard does not calibrate it, so it is the sensor's factory calibration, good to
  // about 1 % (a few centimetres at 3-4 m). Checked on rendered pairs (bench/covariance_bench,
  // each pair's calibration drawn from these sigmas, plus 1 % focal or depth-scale errors, three
  // scenes, every motion of the wide-baseline sweep, five seeds): a depth-scale sigma of 0.5 %
  // left the 1 %-off depth-scale groups' translations 87 % inside the 95 % bound, 0.75 % 91 %,
  // 1 % 93 % (means 5.9, 5.3, 5.0; every other group within its sampling spread). 0.7 % focal
  // left every feature group's mean NEES below 4; 1 %, 2 px, 1 % gave 0.6-2.8 with the earlier
  // information.
  double focal_sigma = 0.005;             // relative, fx and fy each
  double principal_point_sigma_px = 1.0;  // cx and cy each
  double depth_scale_sigma = 0.01;        // relative
  // The unmodelled error no residual shows, per axis: motion_sigma times the motion (angle,
  // distance), levelling off at motion_cap_deg / motion_cap_m (0: no cap):
  //   sigma = motion_sigma * m / sqrt(1 + (motion_sigma * m / cap)^2).
  // Part of it grows with the motion between consecutive frames (depth-colour timing, rolling
  // shutter and the ground truth's own time offset all scale with the speed that motion
  // implies); part is the sensor's accuracy floor (depth bias, depth-colour registration, the
  // ground truth's own error), which a wider baseline does not grow. Measured on the real TUM
  // sets (per-axis RMS error of the returned poses): fr1_desk 8-15 % of 1-9 degree, 1-11 cm
  // motions; fr3_cabinet 0.57-0.78 degrees and 0.9-1.9 cm whether the key frames are 6 or 62
  // degrees and 0.16 or 1.2 m apart. The former linear term (0.05, no cap) read a mean NEES of
  // 20.7 on fr1_desk (36 % inside the 95 % bound) and 0.7 on the wide cabinet pairs (a 1-sigma
  // three to four times the error); these values read 7.0 (83 %), 3.9 (96 %) and 2.0 (100 %) on
  // fr1_desk, fr3_cabinet and its wide pairs (docs/two_view.md, "The motion term"). Rendered
  // pairs (exact timing and ground truth): 0.1-0.5 % of the motion, set motion_sigma to 0.
  double motion_sigma = 0.10;
  double motion_cap_deg = 1.0;
  double motion_cap_m = 0.03;
  // The depth path's slide term (C_slide): a translation 1-sigma along each of camera 2's axes
  // from the depth consistency slide_probe_m away on either side (slideSigmas, slide_search.h),
  // slide_consistency_sigma the consistency's sampling noise (0.0017: a third of the slide
  // search's margin). The alignment's information counts every depth pixel of a plain wall as
  // evidence against a slide along it; the rendered cabinet with a checkerboard calibration's
  // error gave poses 1-4 cm along its wall at a reported 1-sigma under 1 cm. 0: off.
  double slide_probe_m = 0.04;
  double slide_consistency_sigma = 0.0017;
  // Where the feature BA and the depth path's own alignment both accept a pose and agree (path
  // "both"), report their fusion (pose_fusion.h) rather than one of them. false: the one
  // preferDepthPose keeps, with its own covariance.
  bool fuse_agreeing_poses = true;
  std::string validate() const;
};

// A point the pose was estimated from: camera-1 coordinates (m), its pixel sigma in image 2, and
// whether its depth in frame 2 entered the estimate (noise k z^2).
struct CalibrationPoint {
  Eigen::Vector3d X_1;
  double sigma_px = 1.0;
  bool has_depth_2 = false;
};

// What the estimator fits, for the calibration's sensitivity:
//   kReprojection  pixels in image 2 (and depth 2 where given): the feature BA
//   kPoints        3-D points against depth 2's, noise k z^2 on every axis (a cloud alignment)
//   kDense         as kReprojection, and calibrationCovariance adds a focal error's scaling
//                  of the rotation about the image axes (the focal sigma times the rotation).
//                  A focal error does shrink a rotation so (rendered pairs, fx and fy 1 % off at
//                  45-60 degrees: 0.6 % of the rotation), and each estimator's own first-order
//                  shift predicts it (the feature BA's and, from its samples, the alignment's:
//                  least-squares scale 0.94-0.99). The added term counts it a second time, a
//                  margin for focal errors beyond the sigma: without it the 1 %-off focal groups
//                  of covariance_bench read 78 % inside (docs/two_view.md). Both paths use it.
enum class CalibrationMetric { kReprojection, kPoints, kDense };

// The residual a unit error of each calibration parameter (fx, fy relative; cx, cy in pixels of
// `camera`; the depth scale relative) leaves at the true pose T_21 = (R, t) in a measurement of
// the point X_1 that T_21 moves to Y, D its residual's derivative by the moved point. Such an
// error makes every camera-frame point appear as A X, A = I + e dA, in both frames (fx: x read
// as x / (1 + e); cx: x read as x - e z / fx; the depth scale: every point as (1 + e) X). The
// believed point T (A X_1) then lands off where the data put it, A Y, by the apparent motion
// m = R dA X_1 - dA Y, and the residual is D m: column k for parameter k. An estimator's pose
// shifts by the least-squares d that cancels these residuals.
Eigen::Matrix<double, 1, 5> calibrationResiduals(const Eigen::RowVector3d& D,
                                                 const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                                 const Eigen::Vector3d& X_1,
                                                 const Eigen::Vector3d& Y,
                                                 const PinholeCamera& camera);

// Columns: the pose shift d (left perturbation [w, v]) per unit error of fx (relative), fy
// (relative), cx (px), cy (px) and the depth scale (relative). Zero when fewer than 3 points lie
// in front of camera 2 (a pose without support has no covariance to add to).
Eigen::Matrix<double, 6, 5> calibrationSensitivity(
    const std::vector<CalibrationPoint>& points, const SE3Quat& T_21, const PinholeCamera& camera,
    double depth_noise_k, CalibrationMetric metric = CalibrationMetric::kReprojection);

// sum_p sigma_p^2 g_p g_p' with the options' sigmas, g = calibrationSensitivity; kDense adds
// the focal error's scaling of the rotation about the image axes.
Matrix6d calibrationCovariance(const Eigen::Matrix<double, 6, 5>& g, const SE3Quat& T_21,
                               const CovarianceModelOptions& options, CalibrationMetric metric);

// The same from the points.
Matrix6d calibrationCovariance(const std::vector<CalibrationPoint>& points, const SE3Quat& T_21,
                               const PinholeCamera& camera, double depth_noise_k,
                               const CovarianceModelOptions& options,
                               CalibrationMetric metric = CalibrationMetric::kReprojection);

// The 1-sigma a user reads (the CLI's sigma_deg and sigma_cm): sqrt of the trace of the
// rotation block in degrees and of the translation block in centimetres.
struct PoseSigmas {
  double deg = 0, cm = 0;
};
PoseSigmas poseSigmas(const Matrix6d& covariance);

// C_motion of the options for the motion T_21 (diagonal: the rotation's three variances, then
// the translation's).
Matrix6d motionCovariance(const SE3Quat& T_21, const CovarianceModelOptions& options);

// What C_slide adds along camera 2's x, y and z axes (translation variances, m^2): the slide's
// variance less what the alignment's information (`nominal`, the pose's C_information) already
// gives that axis, none where it gives more. Both measure how loosely the pair pins the same
// translation, from different evidence (the consistency profile of the depths; the alignment's
// residuals, overconfident along a plain wall), so the slide is a floor, not a second error:
// added in full, the rendered rooms' depth-path poses read conservative (docs/two_view.md).
Eigen::Vector3d slideVarianceAbove(const Eigen::Vector3d& slide_sigma_m, const Matrix6d& nominal);

// The variance factor chi2 / dof within the options' bounds (1 when dof <= 0 or scaling is off).
double varianceFactor(double chi2, int dof, const CovarianceModelOptions& options);

// A pair's image-2 residual at T_21 normalised by its predicted covariance: pixel noise in both
// images (sigma_px times the pair's sigma_1, sigma_2) and depth-1 noise k z^2 carried along
// camera 1's ray. chi2 with 2 dof when the nominal noise is right.
double pairChi2(const PointPair& pair, const SE3Quat& T_21, const PinholeCamera& camera,
                double pixel_sigma, double depth_noise_k);

// The variance factor s2 of chi2 values (`dof` 1 or 2) of which the inliers are some and the
// outliers lie mostly beyond `gate`: the s2 whose chi2(dof) distribution, cut at `gate`, has
// the median of the values below the gate. A plain chi2 / dof of the inliers would be biased
// low, since the outlier rounds keep only the inliers that fit (at s2 = 6, half of them).
// Within the options' bounds; 1 with fewer than 10 values below the gate or scaling off.
double robustVarianceFactor(const std::vector<double>& chi2, double gate,
                            const CovarianceModelOptions& options, int dof = 2);

// A pair's depth-2 residual at T_21 normalised by its predicted variance: depth noise k z^2 in
// both frames, depth 1's along camera 1's ray. chi2 with 1 dof when the nominal noise is right;
// NaN without depth 2.
double pairDepthChi2(const PointPair& pair, const SE3Quat& T_21, double depth_noise_k);

// Residuals of nearby features share their errors on real sensors (depth-colour misregistration,
// rolling shutter, lens distortion left over): n such features inform the pose like far fewer
// independent ones. The variance inflation 1 + (m - 1) rho, m the mean number of inliers per
// `cell_px` square of image 2, rho their intra-cell correlation (of the whitened image-2
// residual vectors, pooled over cells): 1 for independent noise (rendered pairs), more where
// the residual field is smooth. At least 1. `whitened`: residual / sigma per inlier.
double correlationInflation(const std::vector<Eigen::Vector2d>& pixels,
                            const std::vector<Eigen::Vector2d>& whitened, double cell_px);

// Inliers that coincide, within `radius_px` of another in image 1 and in image 2 (linked
// transitively), share their errors: the mean number of inliers per such group, N / groups
// (1 when none coincide or the radius is 0).
double duplicateInflation(const std::vector<Eigen::Vector2d>& pixels_1,
                          const std::vector<Eigen::Vector2d>& pixels_2, double radius_px);

}  // namespace pnpba
