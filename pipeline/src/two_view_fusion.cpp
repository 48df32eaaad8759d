// The `both` pose: the feature BA's and the depth path's agreeing estimates, fused.
#include <optional>
#include <string>

#include "pnpba/pipeline/covariance_model.h"
#include "pnpba/pipeline/pose_fusion.h"
#include "two_view_stages.h"

namespace pnpba {

namespace {

// A pose of the depth path's own (its RGB-D alignment or registration), not the feature BA.
bool isAlignedPose(const TwoViewResult& r) {
  return r.solver == "rgbd-alignment" || r.solver == "registration";
}

// A result's estimate with the shared terms (calibration, motion) taken out of its covariances.
PoseEstimate ownEstimate(const TwoViewResult& r, const CovarianceModelOptions& model) {
  PoseEstimate e;
  e.T_21 = r.T_21;
  const Matrix6d calibration =
      calibrationCovariance(r.calibration_sensitivity, r.T_21, model, CalibrationMetric::kDense);
  e.own = r.covariance - calibration - motionCovariance(r.T_21, model);
  e.judged = r.judged_covariance - calibration;
  e.nominal = r.nominal_covariance;
  e.calibration_sensitivity = r.calibration_sensitivity;
  return e;
}

}  // namespace

bool fuseAgreeingPoses(const TwoViewResult& features, const std::optional<PoseEstimate>& dense,
                       const cv::Mat& depth1, const cv::Mat& depth2, const Camera& camera,
                       const TwoViewOptions& options, TwoViewResult* kept) {
  const CovarianceModelOptions& model = options.covariance;
  if (!model.fuse_agreeing_poses || !dense || !features.ok || !features.covariance_ok ||
      isAlignedPose(features)) {
    return false;
  }
  PoseEstimate fused;
  if (!fusePoseEstimates(ownEstimate(features, model), *dense, &fused)) {
    return false;
  }
  const Matrix6d calibration = calibrationCovariance(fused.calibration_sensitivity, fused.T_21,
                                                     model, CalibrationMetric::kDense);
  kept->fused = true;
  kept->T_21 = fused.T_21;
  kept->calibration_sensitivity = fused.calibration_sensitivity;
  kept->nominal_covariance = fused.nominal;
  kept->judged_covariance = fused.judged + calibration;
  kept->covariance = fused.own + calibration + motionCovariance(fused.T_21, model);
  kept->slide_sigma_m.setZero();  // inside the fused covariance, no longer the pose's own
  kept->depth_consistency = consistencyOf(fused.T_21, depth1, depth2, camera);
  return true;
}

}  // namespace pnpba
