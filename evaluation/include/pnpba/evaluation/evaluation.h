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

// How the reported covariance C of an estimate fits its error against the ground truth: the
// error as a left perturbation T_est = exp(d) T_true, d = [rotation; translation] in C's order,
// and NEES = d' C^-1 d (chi2 with 6 dof for an honest C: mean 6, 95 % below 12.59). Also whether
// the rotation angle and the translation error lie within twice their reported 1-sigma (sqrt of
// each block's trace, as the CLI's sigma_deg and sigma_cm).
struct CovarianceFit {
  double nees = 0;
  bool inside95 = false;  // NEES <= 12.59
  bool rot_within_2sigma = false, trans_within_2sigma = false;
};
CovarianceFit covarianceFit(const SE3Quat& T_21_estimate, const SE3Quat& T_21_truth,
                            const Matrix6d& covariance);

struct PairOutcome {
  bool ok = false;
  PoseError error;
  double time_ms = 0;
  bool has_covariance = false;  // the method reported one for this pose
  CovarianceFit fit;
};

struct MethodSummary {
  int pairs = 0, failures = 0;
  double median_rot_deg = 0, median_trans_cm = 0, mean_rot_deg = 0, mean_trans_cm = 0;
  double max_rot_deg = 0, max_trans_cm = 0;
  double success_rate = 0;  // solved with rot < 1 deg and trans < 2 cm, over all pairs
  // Solved pairs within the wider limits used for wide baselines and texture-poor scenes, and
  // solved pairs that are wrong (> 10 deg or > 50 cm): a returned pose a user must not trust.
  int within_2deg_5cm = 0, within_5deg_20cm = 0, wrong = 0;
  // Every pair's time, failed ones too: the median, the 95th percentile (the value at the
  // rounded rank 0.95 (n - 1), as the benches' percentile) and the slowest pair.
  double median_time_ms = 0, p95_time_ms = 0, max_time_ms = 0;
  // Over the solved pairs with a covariance (0 when there are none): the NEES median and the
  // shares inside its 95 % bound and within 2 sigma in rotation and in translation. Part of a
  // TUM error is the ground truth's own (docs/evaluation.md).
  int with_covariance = 0;
  double nees_median = 0, nees_inside95 = 0, rot_within_2sigma = 0, trans_within_2sigma = 0;
};

// The value at the rounded rank p (n - 1) of the sorted values (p = 0.5 the median of an odd
// count, 1 the largest), 0 for none: the percentile evaluate_tum and every bench report, so that
// their p95s read alike.
double rankPercentile(std::vector<double> v, double p);

// Statistics over the solved pairs; failures count against the success rate.
MethodSummary summarize(const std::vector<PairOutcome>& outcomes);

}  // namespace pnpba
