#include "pnpba/pipeline/two_view_report.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <utility>

namespace pnpba {

namespace {

// Row-major array of rows.
nlohmann::json matrixJson(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < m.rows(); ++r) {
    nlohmann::json row = nlohmann::json::array();
    for (int c = 0; c < m.cols(); ++c) row.push_back(m(r, c));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

std::string twoViewReportJson(const TwoViewResult& r, const std::string& ba_mode) {
  nlohmann::json j;
  j["ok"] = r.ok;
  if (!r.ok) {
    j["failure"] = r.failure;
    // Which FailureRule refused a solved pose; empty when no pose was solved at all.
    j["failure_rule"] = r.failure_rule;
  }
  j["keypoints"] = {r.counts.keypoints1, r.counts.keypoints2};
  j["matches"] = r.counts.matches;
  j["pairs"] = r.counts.pairs;
  if (r.ok) j["path"] = r.path;                        // features, depth-registration or both
  if (r.ok && r.path == "both") j["fused"] = r.fused;  // the pose is the two paths' fusion
  if (r.ok) j["detector"] = r.detector;                // orb, or sift when the retry found the pose
  j["inliers"] = r.counts.inliers;
  j["rival_inliers"] = r.counts.competitor_inliers;
  if (r.counts.depth_candidates > 0) {
    j["depth_candidates"] = r.counts.depth_candidates;  // the depth path's, aligned
    j["depth_duplicates"] = r.counts.depth_duplicates;  // found to be an earlier one again
  }
  j["inlier_coverage"] = r.inlier_coverage;
  if (r.depth_consistency >= 0) j["depth_consistency"] = r.depth_consistency;
  if (r.registration_fitness >= 0) j["registration_fitness"] = r.registration_fitness;
  if (r.photometric_agreement >= -1 + 1e-12) j["photometric_agreement"] = r.photometric_agreement;
  if (r.overlap >= 0) j["overlap"] = r.overlap;
  j["ba_mode"] = ba_mode;
  j["solver"] = r.solver;
  if (r.ok) {
    const Eigen::Matrix4d T0 = r.T_init.to_homogeneous_matrix();
    j["R_init"] = matrixJson(T0.topLeftCorner<3, 3>());
    j["t_init"] = {T0(0, 3), T0(1, 3), T0(2, 3)};
    j["T"] = matrixJson(r.T_21.to_homogeneous_matrix());
    j["chi2_initial"] = r.chi2_initial;
    j["chi2_final"] = r.chi2_final;
    j["ba_iterations"] = r.ba_iterations;
    j["covariance_order"] = "rotation xyz (rad), translation xyz (m); left perturbation of T_21";
    j["covariance"] = r.covariance_ok ? matrixJson(r.covariance) : nlohmann::json(nullptr);
    if (r.covariance_ok) {
      const PoseSigmas sigma = poseSigmas(r.covariance);
      j["sigma_deg"] = sigma.deg;
      j["sigma_cm"] = sigma.cm;
      // What the fit's residuals scaled the information's pixel and depth noise by
      // (covariance_model.h).
      j["variance_factor"] = r.variance_factor;
      j["depth_variance_factor"] = r.depth_variance_factor;
      // The pose shift per unit error of each calibration parameter (rows in the covariance's
      // order): what a pose graph needs to treat one camera's calibration as shared by its
      // edges rather than drawn anew for each (covariance_model.h).
      j["calibration_order"] =
          "columns fx (relative), fy (relative), cx (px), cy (px), depth scale (relative)";
      j["calibration_sensitivity"] = matrixJson(r.calibration_sensitivity);
      // The depth path's slide term, per camera-2 axis, when it is in the covariance.
      if (!r.slide_sigma_m.isZero()) {
        j["slide_sigma_cm"] = {100 * r.slide_sigma_m.x(), 100 * r.slide_sigma_m.y(),
                               100 * r.slide_sigma_m.z()};
      }
    }
  }
  nlohmann::json& timings = j["timings_ms"] = nlohmann::json::object();
  for (const auto& [name, ms] : r.times_ms.named()) timings[name] = ms;
  timings["total"] = r.times_ms.total_ms;
  return j.dump(2) + "\n";
}

std::string stageTimesLine(const StageTimes& t) {
  std::string line = "time (ms):";
  char text[64];
  const char* separator = " ";
  for (const auto& [name, ms] : t.named()) {
    if (!(ms > 0)) continue;
    std::snprintf(text, sizeof text, "%s%s %.1f", separator, name, ms);
    line += text;
    separator = ", ";
  }
  std::snprintf(text, sizeof text, "; total %.1f", t.total_ms);
  return line + text;
}

}  // namespace pnpba
