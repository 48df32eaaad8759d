// evaluate_tum's work as one library call: every pair (i, i+k), 1 <= k <= max_gap (or k in a
// list of gaps), of a TUM RGB-D sequence or key-frame folder (tum_dataset.h) estimated with each
// requested method and scored against the interpolated ground truth; per-method statistics; the
// reports (JSON, CSV, TUM trajectory) as text.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "pnpba/evaluation/evaluation.h"
#include "pnpba/evaluation/tum_cameras.h"
#include "pnpba/evaluation/tum_dataset.h"
#include "pnpba/pipeline/camera.h"
#include "pnpba/pipeline/covariance_model.h"

namespace pnpba {

struct TumEvaluationOptions {
  std::string folder;       // rgb/, depth/, associate.txt or rgb.txt + depth.txt, groundtruth.txt
  std::string camera_path;  // empty: FOLDER/camera.yaml, else the TUM camera the path names
                            // (sequenceCamera, tum_cameras.h)
  int max_gap = 8;
  std::vector<int> gaps;  // when not empty: only pairs (i, i+k) for these k (max_gap ignored)
  // BA modes (none, pose, textbook, two-camera, rgbd) and "opencv" (the OpenCV baseline).
  std::vector<std::string> methods{"rgbd", "pose", "none", "textbook", "opencv"};
  int features = 1500;     // ORB features for every method
  double gt_offset_s = 0;  // added to image stamps before interpolating the ground truth
  // The reported covariance's model for pnpba's methods (its sigmas: the sensor's calibration).
  CovarianceModelOptions covariance;
  std::string validate() const;  // empty when valid, else names the option
};

// One method on one pair.
struct PairRecord {
  int i = 0, j = 0, k = 0;
  std::string method;
  bool ok = false;
  std::string failure;  // when !ok
  PoseError error;      // when ok
  double time_ms = 0;
  int inliers = 0;
  PoseError motion;  // the ground truth's relative motion (angle, distance)
  // When the method reported a covariance: its 1-sigma (sqrt of each block's trace) and NEES.
  bool has_covariance = false;
  double sigma_deg = 0, sigma_cm = 0, nees = 0;
};

struct TumEvaluation {
  std::string folder;
  std::string camera;  // where the camera came from (SequenceCamera::source)
  double gt_offset_s = 0;
  int max_gap = 0;
  std::vector<std::string> methods;
  int frames = 0, frames_without_ground_truth = 0, frames_missing_files = 0;
  std::vector<PairRecord> records;  // pair by pair, methods in order
  std::map<std::string, MethodSummary> summaries;
  // For the chained trajectory: frame stamps, frame 0's ground truth (if any) and the first
  // method's consecutive estimates T_(i+1)i by i.
  std::vector<double> stamps;
  std::optional<SE3Quat> first_pose;
  std::map<int, SE3Quat> consecutive;
  // The depth path's plugin, opened before the first pair (ms; 0 when already open, -1 when no
  // method needs it): the pairs' times hold none of it.
  double plugin_load_ms = -1;
};

// Throws Error for bad options or input (unreadable sequence, image or depth). `progress` gets
// one line per pair ("pair   0-  1:  rgbd 0.41deg 0.52cm  ...").
TumEvaluation evaluateTumSequence(const TumEvaluationOptions& options,
                                  const std::function<void(const std::string&)>& progress = {});

std::string summaryTable(const TumEvaluation& evaluation);  // the printed per-method table
std::string evaluationJson(const TumEvaluation& evaluation);
std::string evaluationCsv(const TumEvaluation& evaluation);
// The first method's consecutive estimates chained from frame 0's ground truth (identity
// without it) as TUM trajectory lines; a failed step keeps the last pose and is counted in
// *gaps.
std::string chainedTrajectory(const TumEvaluation& evaluation, int* gaps);

}  // namespace pnpba
