#include "pnpba/pipeline/rgbd_alignment.h"

#include <oneapi/tbb/parallel_invoke.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include "brightness_change.h"
#include "pnpba/core/error.h"
#include "rgbd_residuals.h"

namespace pnpba {

namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

// The Huber-weighted normal equations of one kind of residual (photometric or geometric) over
// the bands in order, each residual less gain i1 + offset (brightness_change.h; 0 for the
// geometric ones), with scale sigma, divided by `share`. Of each sample's outer product
// (w J)^T J only the column pairs that hold the lower triangle are summed (12 of its 18
// two-entry packets): the LDLT solve reads nothing else, and each entry is the same product
// (w J_i) J_j as the full outer product's.
void normalEquations(const std::vector<DenseResiduals>& bands, int count,
                     std::vector<DenseResidual> DenseResiduals::*kind, double gain, double offset,
                     double sigma, double huber, double share, Matrix6* H, Vector6* b) {
  Matrix6 h = Matrix6::Zero();
  Vector6 g = Vector6::Zero();
  for (int band = 0; band < count; ++band) {
    for (const DenseResidual& r : bands[band].*kind) {
      // Without a gain (the geometric residuals; the default), i1 is not read.
      const double e = (gain == 0 ? r.value - offset : r.value - gain * r.i1 - offset) / sigma;
      const double w = std::abs(e) <= huber ? 1.0 : huber / std::abs(e);
      const Vector6 wJ = w * r.J.transpose();
      h.col(0) += wJ * r.J(0);
      h.col(1) += wJ * r.J(1);
      h.col(2).tail<4>() += wJ.tail<4>() * r.J(2);
      h.col(3).tail<4>() += wJ.tail<4>() * r.J(3);
      h.col(4).tail<2>() += wJ.tail<2>() * r.J(4);
      h.col(5).tail<2>() += wJ.tail<2>() * r.J(5);
      g += wJ * e;
    }
  }
  h.triangularView<Eigen::StrictlyUpper>() = h.transpose();
  *H = h / (sigma * sigma * share);
  *b = g / (sigma * share);
}

// One kind of residual's robust scale over the bands (robustSigma's); *values is scratch.
double robustSigmaOfBands(const std::vector<DenseResiduals>& bands, int count,
                          std::vector<DenseResidual> DenseResiduals::*kind, double floor,
                          double offset, std::vector<double>* values) {
  values->clear();
  for (int band = 0; band < count; ++band) {
    for (const DenseResidual& r : bands[band].*kind) values->push_back(std::abs(r.value - offset));
  }
  return robustSigmaOf(values, floor);
}

// The normal equations of every dense residual at the current pose: the photometric ones less
// the frames' brightness change (brightness_change.h), each kind at its own robust scale. The
// two kinds are independent and summed on both cores, each in the bands' order: the same sums
// as over the joined residuals, photometric then geometric.
void denseNormalEquations(const std::vector<DenseResiduals>& bands, int count,
                          const RgbdAlignmentOptions& o, Matrix6* H, Vector6* b) {
  Matrix6 H_photometric, H_geometric;
  Vector6 b_photometric, b_geometric;
  tbb::parallel_invoke(
      [&] {
        thread_local std::vector<double> values;
        thread_local std::vector<const std::vector<DenseResidual>*> spans;
        spans.clear();
        for (int band = 0; band < count; ++band) spans.push_back(&bands[band].photometric);
        const BrightnessChange change =
            fitBrightnessChange(spans, o.brightness_gain_sigma, o.huber_sigmas, 1.0, &values);
        normalEquations(bands, count, &DenseResiduals::photometric, change.gain, change.offset,
                        change.sigma, o.huber_sigmas, o.correlated_samples, &H_photometric,
                        &b_photometric);
      },
      [&] {
        thread_local std::vector<double> values;
        const double sigma =
            robustSigmaOfBands(bands, count, &DenseResiduals::geometric, 0.1, 0.0, &values);
        normalEquations(bands, count, &DenseResiduals::geometric, 0.0, 0.0, sigma, o.huber_sigmas,
                        o.correlated_samples, &H_geometric, &b_geometric);
      });
  *H = H_photometric + H_geometric;
  *b = b_photometric + b_geometric;
}

}  // namespace

std::string RgbdAlignmentOptions::validate() const {
  if (levels < 1 || iterations < 1) return "rgbd alignment: levels and iterations must be >= 1";
  if (finest_stride < 1) return "rgbd alignment: stride must be >= 1";
  if (finest_level < 0 || finest_level >= levels) {
    return "rgbd alignment: finest level must be in [0, levels)";
  }
  for (double v :
       {huber_sigmas, depth_noise_floor_m, correlated_samples, feature_gate_px, converged_step}) {
    if (!(v > 0) || !std::isfinite(v)) return "rgbd alignment: widths and scales must be > 0";
  }
  if (!(depth_noise_k >= 0)) return "rgbd alignment: depth noise must be >= 0";
  if (!(settled_step_sigmas >= 0) || !std::isfinite(settled_step_sigmas)) {
    return "rgbd alignment: the settled step must be finite and >= 0";
  }
  if (!(brightness_gain_sigma >= 0) || !std::isfinite(brightness_gain_sigma)) {
    return "rgbd alignment: the brightness gain's sigma must be finite and >= 0";
  }
  return "";
}

RgbdAlignment alignRgbd(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                        const cv::Mat& depth2, const PinholeCamera& camera, double depth_scale,
                        const SE3Quat& T_seed, const std::vector<AlignmentFeature>& features,
                        const RgbdAlignmentOptions& o) {
  const std::string problem = o.validate();
  if (!problem.empty()) throw Error(problem);
  const auto start = std::chrono::steady_clock::now();
  RgbdAlignment out =
      alignRgbdPyramid(rgbdPyramid(image1, depth1, image2, depth2, camera, depth_scale, o.levels),
                       camera, T_seed, features, o);
  out.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return out;
}

RgbdAlignment alignRgbdPyramid(const std::vector<RgbdLevel>& pyramid, const PinholeCamera& camera,
                               const SE3Quat& T_seed, const std::vector<AlignmentFeature>& features,
                               const RgbdAlignmentOptions& o,
                               std::chrono::steady_clock::time_point deadline) {
  const auto start = std::chrono::steady_clock::now();
  RgbdAlignment out;
  DenseResidualOptions dense;
  dense.depth_noise_k = o.depth_noise_k;
  dense.depth_noise_floor_m = o.depth_noise_floor_m;
  PinholeCamera feature_camera = camera;
  feature_camera.distortion = {};
  SE3Quat T = T_seed;
  std::vector<char> active(features.size(), 0);
  DenseResidualWorkspace workspace;
  const int levels = std::min(static_cast<int>(pyramid.size()), o.levels);
  const int finest = std::max(0, std::min(o.finest_level, levels - 1));
  // Each level's last step time on this thread (a deadline's guess of the next step's; the depth
  // path aligns several candidates on one pyramid, level 0 often in a call of its own).
  thread_local std::array<std::chrono::steady_clock::duration, 8> last_step{};
  for (int level = levels - 1; level >= finest; --level) {
    const size_t slot = static_cast<size_t>(std::min(level, 7));
    // Level 0 at the finest stride; level 1 samples a quarter as many pixels and each coarser
    // level as many as level 1 (most iterations run there, and a quarter image needs no more to
    // find its basin).
    dense.stride = std::max(1, o.finest_stride >> std::max(0, level - 1));
    // The features in play are decided once per level, so that a pair cannot leave the cost by
    // being pushed out of the gate.
    for (size_t i = 0; i < features.size(); ++i) {
      const Eigen::Vector3d X = T.map(features[i].X_1);
      active[i] =
          X.z() > 0.05 && (feature_camera.project(X) - features[i].uv_2).norm() < o.feature_gate_px;
    }
    for (int it = 0; it < o.iterations; ++it) {
      // A step starts only where it would end by the deadline, taken to cost what this level's
      // last step did.
      const auto step_start = std::chrono::steady_clock::now();
      if (deadline != std::chrono::steady_clock::time_point::max() &&
          step_start + last_step[slot] >= deadline) {
        out.out_of_time = true;
        out.failure = "the RGB-D alignment ran out of time";
        break;
      }
      const int bands = denseResidualBands(pyramid[level], T, dense, false, &workspace);
      size_t geometric = 0;
      for (int band = 0; band < bands; ++band) geometric += workspace.bands[band].geometric.size();
      constexpr size_t kMinSamples = 30;
      if (geometric < kMinSamples) {
        out.failure = "too little of the two frames overlaps for the RGB-D alignment";
        break;
      }
      Matrix6 H;
      Vector6 b;
      denseNormalEquations(workspace.bands, bands, o, &H, &b);
      for (size_t i = 0; i < features.size(); ++i) {
        if (!active[i]) continue;
        const Eigen::Vector3d X = T.map(features[i].X_1);
        const Eigen::Matrix<double, 2, 6> J =
            projectionJacobian(feature_camera, X) / features[i].sigma_px;
        const Eigen::Vector2d e =
            (feature_camera.project(X) - features[i].uv_2) / features[i].sigma_px;
        const double w = e.norm() <= o.huber_sigmas ? 1.0 : o.huber_sigmas / e.norm();
        H.noalias() += w * J.transpose() * J;
        b.noalias() += w * J.transpose() * e;
      }
      const Eigen::LDLT<Matrix6> ldlt(H);
      if (ldlt.info() != Eigen::Success) break;
      Vector6 step = -ldlt.solve(b);
      if (!step.allFinite()) break;
      // A Gauss-Newton step on a robust, re-weighted cost can overshoot far from the minimum;
      // limit it to what one level can resolve.
      const double limit = 0.1 * (1 << level);
      const double size = std::max(step.head<3>().norm() / 0.1, step.tail<3>().norm() / limit);
      if (size > 1.0) step /= size;
      T = SE3Quat::exp(step) * T;
      ++out.iterations;
      last_step[slot] = std::chrono::steady_clock::now() - step_start;
      if (step.head<3>().norm() < o.converged_step && step.tail<3>().norm() < o.converged_step) {
        break;
      }
      const double settled = o.settled_step_sigmas;
      if (level == 0 && it >= 2 && step.dot(H * step) < settled * settled) break;
    }
    if (!out.failure.empty()) break;
  }
  for (size_t i = 0; i < features.size(); ++i) {
    const Eigen::Vector3d X = T.map(features[i].X_1);
    out.feature_inliers +=
        X.z() > 0.05 && (feature_camera.project(X) - features[i].uv_2).norm() < o.feature_gate_px;
  }
  out.T_21 = T;
  out.ok = out.failure.empty() && T.to_homogeneous_matrix().allFinite();
  if (!out.ok && out.failure.empty()) out.failure = "the RGB-D alignment diverged";
  out.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace pnpba
