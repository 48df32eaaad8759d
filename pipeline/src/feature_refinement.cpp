// The feature path's bundle adjustment and the covariance the model reports for its pose
// (covariance_model.h): the fit's own variance factors, the residuals' correlation, the
// calibration and the motion terms. The driver (two_view.cpp) calls refineInto.
#include <oneapi/tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "pnpba/pipeline/covariance_model.h"
#include "pnpba/pipeline/pose_graph.h"
#include "pnpba/pipeline/pose_refinement.h"
#include "two_view_stages.h"

namespace pnpba {

// The fit's variance factor reads the pairs whose chi2 is below this many times the outlier
// rounds' limit: up to 2 px where the rounds stop at 1 px, so that noise of twice the nominal is
// measured, not cut off (robustVarianceFactor corrects for the rest of the cut).
constexpr double kFitGateFactor = 4.0;

namespace {

// The BA's pose covariance with its pixel noise variance scaled by `factors[i].first` and its
// depth noise variance by `.second`, for each i. Covariance is linear in a common scale, so
// each is pixel * (C_ba + D(depth / pixel) - D(1)), D(r) the graph's covariance with the depth
// variance r times the nominal (rgbdPoseCovariances): exactly pixel * C_ba where they agree.
std::vector<Matrix6d> scaledBaCovariances(const std::vector<PointPair>& ba_pairs,
                                          const Refinement& ba, const PinholeCamera& geometry,
                                          const RefinementOptions& o,
                                          const std::vector<std::pair<double, double>>& factors) {
  std::vector<Matrix6d> out;
  std::vector<double> depth_k{o.depth_noise_k};  // D(1), then D(r) of every r != 1
  std::vector<size_t> setting(factors.size(), 0);
  for (size_t i = 0; i < factors.size(); ++i) {
    const auto [pixel, depth] = factors[i];
    out.push_back(pixel * ba.covariance);
    if (depth == pixel) continue;
    setting[i] = depth_k.size();
    depth_k.push_back(o.depth_noise_k * std::sqrt(depth / pixel));
  }
  if (o.mode != BundleMode::kRgbd || !ba.covariance_ok || depth_k.size() == 1 ||
      ba.depth2.size() != ba_pairs.size()) {
    return out;
  }
  std::vector<PointPair> inliers;
  std::vector<char> depth2;
  for (size_t k = 0; k < ba_pairs.size(); ++k) {
    if (!ba.inlier[k]) continue;
    inliers.push_back(ba_pairs[k]);
    depth2.push_back(ba.depth2[k]);
  }
  PoseGraphOptions g;
  g.intrinsics = geometry;
  g.pixel_sigma = o.pixel_sigma;
  std::vector<Matrix6d> D;
  if (!rgbdPoseCovariances(inliers, depth2, ba.T_21, g, depth_k, &D)) return out;
  for (size_t i = 0; i < factors.size(); ++i) {
    if (setting[i] != 0) out[i] += factors[i].first * (D[setting[i]] - D[0]);
  }
  return out;
}

// The reported covariance of a BA pose (covariance_model.h): the nominal information with the
// pixel and depth noise each scaled by the fit's own variance factor and both by the residuals'
// correlation, plus the calibration term over the inliers and the motion term. The failure rule
// judges it with the factors read as at least 1 and without the motion term.
void modelCovariance(const std::vector<PointPair>& ba_pairs, const Refinement& ba,
                     const PinholeCamera& geometry, const TwoViewOptions& options,
                     TwoViewResult* r) {
  const RefinementOptions& o = options.refinement;
  // Depth first: the image-2 residuals carry depth 1's noise along its ray.
  std::vector<double> depth_chi2;
  for (size_t k = 0; k < ba_pairs.size(); ++k) {
    if (!ba.inlier[k]) continue;
    const double c = pairDepthChi2(ba_pairs[k], ba.T_21, o.depth_noise_k);
    if (std::isfinite(c)) depth_chi2.push_back(c);
  }
  const double depth_factor =
      robustVarianceFactor(depth_chi2, kFitGateFactor * o.depth2_gate_chi2, options.covariance, 1);
  std::vector<double> chi2;
  for (const PointPair& p : ba_pairs) {
    chi2.push_back(
        pairChi2(p, ba.T_21, geometry, o.pixel_sigma, o.depth_noise_k * std::sqrt(depth_factor)));
  }
  const double pixel_factor =
      robustVarianceFactor(chi2, kFitGateFactor * o.outlier_chi2, options.covariance);
  std::vector<Eigen::Vector2d> pixels_1, pixels, whitened;
  std::vector<CalibrationPoint> points;
  for (size_t k = 0; k < ba_pairs.size(); ++k) {
    if (!ba.inlier[k]) continue;
    const PointPair& p = ba_pairs[k];
    const double sigma = o.pixel_sigma * p.sigma_2;
    pixels_1.push_back(p.uv_1);
    pixels.push_back(p.uv_2);
    whitened.push_back((geometry.project(ba.T_21.map(p.X_1)) - p.uv_2) / sigma);
    points.push_back({p.X_1, sigma, std::isfinite(p.depth_2)});
  }
  const double inflation =
      (options.covariance.correlation_inflation
           ? correlationInflation(pixels, whitened, options.covariance.correlation_cell_px)
           : 1.0) *
      duplicateInflation(pixels_1, pixels, options.covariance.duplicate_radius_px);
  r->variance_factor = pixel_factor * inflation;
  r->depth_variance_factor = depth_factor * inflation;
  r->calibration_sensitivity =
      calibrationSensitivity(points, ba.T_21, geometry, o.depth_noise_k, CalibrationMetric::kDense);
  const Matrix6d calibration = calibrationCovariance(r->calibration_sensitivity, ba.T_21,
                                                     options.covariance, CalibrationMetric::kDense);
  const std::vector<Matrix6d> information = scaledBaCovariances(
      ba_pairs, ba, geometry, o,
      {{r->variance_factor, r->depth_variance_factor},
       {std::max(1.0, r->variance_factor), std::max(1.0, r->depth_variance_factor)}});
  r->covariance = information[0] + calibration + motionCovariance(ba.T_21, options.covariance);
  r->judged_covariance = information[1] + calibration;
}

// Whether a pair passes RANSAC's own test at T once depth 1's noise is counted: its image-2
// reprojection error within threshold_px in units of RANSAC's 1-px pixel noise plus depth 1's
// noise along the point's ray (pairChi2 without image 1's pixel noise).
bool agreesCountingDepthNoise(const PointPair& pair, const SE3Quat& T, const PinholeCamera& camera,
                              double threshold_px, double depth_noise_k) {
  PointPair p = pair;
  p.sigma_1 = 0;
  p.sigma_2 = 1;
  return pairChi2(p, T, camera, 1.0, depth_noise_k) < threshold_px * threshold_px;
}

}  // namespace

// Bundle adjustment from T_init over the pairs flagged in `use`; fills r's pose, chi2,
// covariance, inliers. False (r->failure set) when too few inliers survive.
bool refineInto(const FeatureStage& stage, const std::vector<char>& use, const SE3Quat& T_init,
                const cv::Mat& depth2, const TwoViewOptions& options, TwoViewResult* r,
                const std::function<void()>& alongside) {
  const auto t = Clock::now();
  // The pairs `use` flags, and every other pair RANSAC's test passes at T_init once depth 1's
  // noise is counted. Where the baseline is small that noise barely moves a pixel and the set is
  // `use`; across a wide one it moves a far point's pixel several pixels along its epipolar line,
  // and the pixel threshold alone kept the pairs whose depth errors happened to agree with the
  // RANSAC pose, whose error the refined pose then inherited (twice the depth noise's `both`
  // poses at two seeds: 80 -> 100 % inside their 95 % bound; docs/two_view.md). The BA's outlier
  // rounds then judge every pair held here.
  std::vector<PointPair> ba_pairs;
  std::vector<size_t> ba_index;
  for (size_t i = 0; i < r->pairs.size(); ++i) {
    const Correspondence& c = r->pairs[i];
    PointPair p{c.X_1, c.uv_2, c.uv_1};
    if (!use[i] && !agreesCountingDepthNoise(p, T_init, stage.geometry, options.ransac.threshold_px,
                                             options.refinement.depth_noise_k)) {
      continue;
    }
    p.sigma_1 = keypointSigma(stage.f1, c.keypoint_1, options);
    p.sigma_2 = keypointSigma(stage.f2, c.keypoint_2, options);
    if (!depth2.empty()) {
      const cv::Point2f& raw2 = stage.f2.keypoints[c.keypoint_2].pt;
      if (auto z2 = depthAt(depth2, raw2.x, raw2.y, stage.depth_options)) p.depth_2 = *z2;
    }
    ba_pairs.push_back(p);
    ba_index.push_back(i);
  }
  const Refinement ba = refinePose(ba_pairs, T_init, stage.geometry, options.refinement);
  r->inlier.assign(r->pairs.size(), 0);
  for (size_t k = 0; k < ba_index.size(); ++k) r->inlier[ba_index[k]] = ba.inlier[k];
  r->counts.inliers = ba.num_inliers;
  r->T_21 = ba.T_21;
  r->chi2_initial = ba.chi2_initial;
  r->chi2_final = ba.chi2_final;
  r->ba_iterations = ba.iterations;
  r->solver = ba.solver;
  r->nominal_covariance = ba.covariance;
  r->covariance_ok = ba.covariance_ok;
  // The covariance model (0.5-0.7 ms on fr1_desk's pairs) is serial; what the caller measures
  // at the refined pose (the feature path: the inliers' area and the depth consistency, 0.3-0.4
  // ms) runs beside it instead of after it. Each writes its own fields of *r.
  const bool refined =
      ba.num_inliers >= options.ransac.min_inliers && r->T_21.to_homogeneous_matrix().allFinite();
  if (alongside && refined) {
    tbb::parallel_invoke([&] { modelCovariance(ba_pairs, ba, stage.geometry, options, r); },
                         alongside);
  } else {
    modelCovariance(ba_pairs, ba, stage.geometry, options, r);
  }
  r->times_ms.ba_ms += msSince(t);
  if (ba.num_inliers < options.ransac.min_inliers) {
    r->failure = std::to_string(ba.num_inliers) + " inliers after BA < " +
                 std::to_string(options.ransac.min_inliers) + " required";
    return false;
  }
  if (!r->T_21.to_homogeneous_matrix().allFinite()) {
    r->failure = "bundle adjustment diverged";
    return false;
  }
  return true;
}

}  // namespace pnpba
