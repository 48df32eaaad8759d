// Relative pose error of a two-view estimate against ground truth, and the statistics an
// evaluation table reports.
#pragma once

#include <string>
#include <vector>

#include "pnpba/optimize/se3_quat.h"

namespace pnpba {

struct PoseError {
  double rot_deg = 0;   // angle of R_est R_true^T
  double trans_cm = 0;  // |t_est - t_true|
};

PoseError relativePoseError(const SE3Quat& T_21_estimate, const SE3Quat& T_21_truth);
// T_21 from camera-to-world poses of frames 1 and 2: X2 = T_21 X1.
SE3Quat relativePose(const SE3Quat& T_wc1, const SE3Quat& T_wc2);

struct PairOutcome {
  bool ok = false;
  PoseError error;
  double time_ms = 0;
};

struct MethodSummary {
  int pairs = 0, failures = 0;
  double median_rot_deg = 0, median_trans_cm = 0, mean_rot_deg = 0, mean_trans_cm = 0;
  double max_rot_deg = 0, max_trans_cm = 0;
  double success_rate = 0;  // solved with rot < 1 deg and trans < 2 cm, over all pairs
  // Solved pairs within the wider limits used for wide baselines and texture-poor scenes, and
  // solved pairs that are wrong (> 10 deg or > 50 cm): a returned pose a user must not trust.
  int within_2deg_5cm = 0, within_5deg_20cm = 0, wrong = 0;
  double median_time_ms = 0;
};

// Statistics over the solved pairs; failures count against the success rate.
MethodSummary summarize(const std::vector<PairOutcome>& outcomes);

}  // namespace pnpba
