#include "pnpba/evaluation/evaluation.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "pnpba/pipeline/covariance_model.h"

namespace pnpba {

namespace {
double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
double mean(const std::vector<double>& v) {
  return v.empty() ? 0 : std::accumulate(v.begin(), v.end(), 0.0) / v.size();
}
}  // namespace

double rankPercentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(p * (v.size() - 1) + 0.5))];
}

PoseError relativePoseError(const SE3Quat& T_21_estimate, const SE3Quat& T_21_truth) {
  const Eigen::Matrix3d R = T_21_estimate.rotation().toRotationMatrix() *
                            T_21_truth.rotation().toRotationMatrix().transpose();
  const double c = std::clamp((R.trace() - 1.0) / 2.0, -1.0, 1.0);
  return {std::acos(c) * 180.0 / M_PI,
          (T_21_estimate.translation() - T_21_truth.translation()).norm() * 100.0};
}

CovarianceFit covarianceFit(const SE3Quat& T_21_estimate, const SE3Quat& T_21_truth,
                            const Matrix6d& covariance) {
  constexpr double kChi2_6dof_95 = 12.592;
  const Eigen::Matrix<double, 6, 1> d = (T_21_estimate * T_21_truth.inverse()).log();
  CovarianceFit fit;
  fit.nees = d.dot(covariance.ldlt().solve(d));
  fit.inside95 = fit.nees <= kChi2_6dof_95;
  const PoseError e = relativePoseError(T_21_estimate, T_21_truth);
  const PoseSigmas sigma = poseSigmas(covariance);
  fit.rot_within_2sigma = e.rot_deg <= 2 * sigma.deg;
  fit.trans_within_2sigma = e.trans_cm <= 2 * sigma.cm;
  return fit;
}

SE3Quat relativePose(const SE3Quat& T_wc1, const SE3Quat& T_wc2) { return T_wc2.inverse() * T_wc1; }

MethodSummary summarize(const std::vector<PairOutcome>& outcomes) {
  MethodSummary s;
  s.pairs = static_cast<int>(outcomes.size());
  std::vector<double> rot, trans, times, nees;
  int successes = 0, inside95 = 0, rot_2sigma = 0, trans_2sigma = 0;
  for (const PairOutcome& o : outcomes) {
    times.push_back(o.time_ms);
    if (!o.ok) {
      ++s.failures;
      continue;
    }
    rot.push_back(o.error.rot_deg);
    trans.push_back(o.error.trans_cm);
    if (o.error.rot_deg < 1.0 && o.error.trans_cm < 2.0) ++successes;
    if (o.error.rot_deg < 2.0 && o.error.trans_cm < 5.0) ++s.within_2deg_5cm;
    if (o.error.rot_deg < 5.0 && o.error.trans_cm < 20.0) ++s.within_5deg_20cm;
    if (o.error.rot_deg > 10.0 || o.error.trans_cm > 50.0) ++s.wrong;
    if (o.has_covariance) {
      nees.push_back(o.fit.nees);
      inside95 += o.fit.inside95;
      rot_2sigma += o.fit.rot_within_2sigma;
      trans_2sigma += o.fit.trans_within_2sigma;
    }
  }
  s.with_covariance = static_cast<int>(nees.size());
  if (!nees.empty()) {
    const double n = static_cast<double>(nees.size());
    s.nees_median = median(nees);
    s.nees_inside95 = inside95 / n;
    s.rot_within_2sigma = rot_2sigma / n;
    s.trans_within_2sigma = trans_2sigma / n;
  }
  s.median_rot_deg = median(rot);
  s.median_trans_cm = median(trans);
  s.mean_rot_deg = mean(rot);
  s.mean_trans_cm = mean(trans);
  s.max_rot_deg = rot.empty() ? 0 : *std::max_element(rot.begin(), rot.end());
  s.max_trans_cm = trans.empty() ? 0 : *std::max_element(trans.begin(), trans.end());
  s.success_rate = s.pairs > 0 ? static_cast<double>(successes) / s.pairs : 0;
  s.median_time_ms = median(times);
  s.p95_time_ms = rankPercentile(times, 0.95);
  s.max_time_ms = rankPercentile(times, 1.0);
  return s;
}

}  // namespace pnpba
