#include "pnpba/pipeline/failure_rule.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "pnpba/pipeline/covariance_model.h"

namespace pnpba {

std::string FailureRule::validate() const {
  if (min_inliers < 0) return "failure rule: min inliers must be >= 0";
  if (!(min_inlier_ratio >= 0 && min_inlier_ratio <= 1)) {
    return "failure rule: min inlier ratio must be in [0, 1]";
  }
  if (!(min_depth_consistency >= 0 && min_depth_consistency <= 1) ||
      !(min_registration_consistency >= 0 && min_registration_consistency <= 1)) {
    return "failure rule: min depth consistency must be in [0, 1]";
  }
  for (double v : {max_chi2_per_inlier, max_competitor_ratio, max_undetermined_sigma_deg,
                   max_undetermined_sigma_m}) {
    if (!(v > 0)) return "failure rule: chi2, competitor and undetermined limits must be > 0";
  }
  if (!(max_sigma_deg >= 0) || !(max_sigma_cm >= 0) || !std::isfinite(max_sigma_deg) ||
      !std::isfinite(max_sigma_cm)) {
    return "max sigma limits must be >= 0 (0: off)";
  }
  return "";
}

FailureVerdict FailureRule::check(const PoseEvidence& e) const {
  if (!enabled) return {};
  char text[200];
  auto refuse = [&text](const char* rule) { return FailureVerdict{rule, text}; };
  if (e.inliers < min_inliers) {
    std::snprintf(text, sizeof text, "%d inliers < %d required", e.inliers, min_inliers);
    return refuse("inliers");
  }
  const double ratio = e.pairs > 0 ? static_cast<double>(e.inliers) / e.pairs : 0.0;
  if (ratio < min_inlier_ratio) {
    std::snprintf(text, sizeof text, "inlier ratio %.2f (%d of %d pairs) < %.2f", ratio, e.inliers,
                  e.pairs, min_inlier_ratio);
    return refuse("inlier_ratio");
  }
  if (e.chi2_final / e.inliers > max_chi2_per_inlier) {
    std::snprintf(text, sizeof text, "chi2 per inlier %.2f > %.2f", e.chi2_final / e.inliers,
                  max_chi2_per_inlier);
    return refuse("chi2");
  }
  if (e.competitor_inliers > max_competitor_ratio * e.inliers) {
    std::snprintf(
        text, sizeof text,
        "ambiguous: a rival pose explains %d pairs the estimate does not (it has %d inliers)",
        e.competitor_inliers, e.inliers);
    return refuse("ambiguous");
  }
  if (ratio < local_fit_ratio && e.inlier_coverage < min_inlier_coverage) {
    std::snprintf(text, sizeof text,
                  "local fit: the inliers cover %.0f %% of the matched area and %.0f %% of the "
                  "pairs",
                  100.0 * e.inlier_coverage, 100.0 * ratio);
    return refuse("local_fit");
  }
  if (e.depth_consistency >= 0 && e.depth_consistency < min_depth_consistency) {
    std::snprintf(text, sizeof text,
                  "depths contradict the pose: consistency %.2f < %.2f (points land in front of "
                  "surfaces the other camera sees)",
                  e.depth_consistency, min_depth_consistency);
    return refuse("depth_inconsistent");
  }
  if (e.covariance_ok) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> rot(e.covariance.topLeftCorner<3, 3>());
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> trans(e.covariance.bottomRightCorner<3, 3>());
    const double worst_deg = std::sqrt(std::max(rot.eigenvalues()(2), 0.0)) * 180.0 / M_PI;
    const double worst_m = std::sqrt(std::max(trans.eigenvalues()(2), 0.0));
    if (worst_deg > max_undetermined_sigma_deg || worst_m > max_undetermined_sigma_m) {
      std::snprintf(text, sizeof text,
                    "degenerate geometry: 1-sigma along the worst direction %.1f deg, %.1f cm",
                    worst_deg, worst_m * 100.0);
      return refuse("degenerate");
    }
    const PoseSigmas sigma = poseSigmas(e.covariance);
    const double rot_sigma = sigma.deg, trans_sigma = sigma.cm;
    if ((max_sigma_deg > 0 && rot_sigma > max_sigma_deg) ||
        (max_sigma_cm > 0 && trans_sigma > max_sigma_cm)) {
      std::snprintf(text, sizeof text,
                    "pose less precise than asked: 1-sigma %.2f deg, %.2f cm (limits %.2f deg, "
                    "%.2f cm)",
                    rot_sigma, trans_sigma, max_sigma_deg, max_sigma_cm);
      return refuse("max_sigma");
    }
  }
  return {};
}

}  // namespace pnpba
