#include "pnpba/pipeline/alignment_evidence.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "brightness_change.h"
#include "pnpba/pipeline/covariance_model.h"
#include "rgbd_residuals.h"

namespace pnpba {

namespace {

// The brightness fit's Huber width: the alignment's (RgbdAlignmentOptions::huber_sigmas).
constexpr double kHuberSigmas = 1.345;

// Zero-mean normalised cross-correlation.
double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const double ma = std::accumulate(a.begin(), a.end(), 0.0) / a.size();
  const double mb = std::accumulate(b.begin(), b.end(), 0.0) / b.size();
  double saa = 0, sbb = 0, sab = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
    sab += (a[i] - ma) * (b[i] - mb);
  }
  return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0.0;
}

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

// The scores g_c of square cells of frame-1 pixels (points outside the image count in the
// nearest cell) and their scatter G / (G - 1) sum g_c g_c^T over the G cells used.
class CellScores {
 public:
  CellScores(cv::Size image, int cell_px)
      : cell_(cell_px),
        cols_((image.width + cell_px - 1) / cell_px),
        rows_((image.height + cell_px - 1) / cell_px),
        score_(static_cast<size_t>(std::max(1, cols_ * rows_)), Vector6::Zero()),
        used_(score_.size(), 0) {}

  void add(double u, double v, const Vector6& g) {
    const int x = std::clamp(static_cast<int>(std::floor(u / cell_)), 0, std::max(0, cols_ - 1));
    const int y = std::clamp(static_cast<int>(std::floor(v / cell_)), 0, std::max(0, rows_ - 1));
    const size_t i = static_cast<size_t>(y) * std::max(1, cols_) + x;
    score_[i] += g;
    used_[i] = 1;
  }
  int used() const { return static_cast<int>(std::count(used_.begin(), used_.end(), 1)); }
  // sum_c g_c: the gradient of every sample added.
  Vector6 total() const {
    Vector6 sum = Vector6::Zero();
    for (const Vector6& g : score_) sum += g;
    return sum;
  }
  Matrix6 scatter() const {
    Matrix6 S = Matrix6::Zero();
    for (size_t i = 0; i < score_.size(); ++i) {
      if (used_[i]) S.noalias() += score_[i] * score_[i].transpose();
    }
    const int g = used();
    return g > 1 ? S * (static_cast<double>(g) / (g - 1)) : S;
  }

 private:
  int cell_, cols_, rows_;
  std::vector<Vector6> score_;
  std::vector<char> used_;
};

// The inverse of a symmetric positive-definite A; false when a direction has (numerically) no
// information.
bool invertible(const Matrix6& A, Matrix6* inverse) {
  Eigen::SelfAdjointEigenSolver<Matrix6> eig(A);
  if (eig.info() != Eigen::Success || !(eig.eigenvalues()(0) > 0) ||
      !(eig.eigenvalues()(0) > 1e-12 * eig.eigenvalues()(5))) {
    return false;
  }
  *inverse = eig.eigenvectors() * eig.eigenvalues().cwiseInverse().asDiagonal() *
             eig.eigenvectors().transpose();
  return inverse->allFinite();
}

}  // namespace

std::string AlignmentEvidenceOptions::validate() const {
  if (stride < 1 || cell_px < 1) return "alignment evidence: stride and cell size must be >= 1";
  for (double v : {depth_noise_floor_m, gate_sigmas, feature_gate_px}) {
    if (!(v > 0) || !std::isfinite(v)) return "alignment evidence: widths and scales must be > 0";
  }
  if (!(resolution_px >= 0 && depth_resolution >= 0) || !std::isfinite(resolution_px) ||
      !std::isfinite(depth_resolution) || (resolution_px > 0) != (depth_resolution > 0)) {
    return "alignment evidence: resolutions must be both > 0 (or both 0: no floor)";
  }
  if (!(depth_noise_k >= 0)) return "alignment evidence: depth noise must be >= 0";
  if (!(brightness_gain_sigma >= 0) || !std::isfinite(brightness_gain_sigma)) {
    return "alignment evidence: the brightness gain's sigma must be finite and >= 0";
  }
  return "";
}

AlignmentEvidence measureAlignment(const cv::Mat& image1, const cv::Mat& depth1,
                                   const cv::Mat& image2, const cv::Mat& depth2,
                                   const PinholeCamera& camera, double depth_scale,
                                   const SE3Quat& T_21,
                                   const std::vector<AlignmentFeature>& features,
                                   const AlignmentEvidenceOptions& o) {
  return measureAlignmentAt(rgbdPyramid(image1, depth1, image2, depth2, camera, depth_scale, 1)[0],
                            camera, T_21, features, o);
}

AlignmentEvidence measureAlignmentAt(const RgbdLevel& level0, const PinholeCamera& camera,
                                     const SE3Quat& T_21,
                                     const std::vector<AlignmentFeature>& features,
                                     const AlignmentEvidenceOptions& o) {
  AlignmentEvidence out;
  DenseResidualOptions dense;
  dense.stride = o.stride;
  dense.depth_noise_k = o.depth_noise_k;
  dense.depth_noise_floor_m = o.depth_noise_floor_m;
  DenseResiduals r = denseResiduals(level0, T_21, dense);
  out.depth1_samples = r.depth1_samples;
  constexpr size_t kMinSamples = 30;
  if (r.geometric.size() < kMinSamples) return out;

  // A brightness change between the frames (auto exposure) is not pose error.
  std::vector<double> scratch;
  const BrightnessChange change =
      fitBrightnessChange({&r.photometric}, o.brightness_gain_sigma, kHuberSigmas, 1.0, &scratch);
  for (DenseResidual& s : r.photometric) s.value = change.residual(s);
  out.geometric_scale = robustSigma(r.geometric, 0.1);
  out.photometric_sigma = change.sigma;
  out.photometric_agreement = correlation(r.intensity1, r.intensity2);

  // Over the gated samples and the feature pairs: the information H, each cell's score g_c and
  // the samples' mean pixel information M (header).
  // b: the calibration's pull on the samples (header; calibrationResiduals).
  CellScores cells(level0.grey1.size(), o.cell_px);
  Matrix6 H = Matrix6::Zero(), M = Matrix6::Zero();
  Eigen::Matrix<double, 6, 5> b = Eigen::Matrix<double, 6, 5>::Zero();
  int m_samples = 0;
  const Eigen::Matrix3d R = T_21.rotation().toRotationMatrix();
  const Eigen::Vector3d t = T_21.translation();
  auto accumulate = [&](const std::vector<DenseResidual>& samples, double sigma, bool pixels,
                        int* used) {
    const double gate = o.gate_sigmas * sigma;
    for (size_t i = 0; i < samples.size(); ++i) {
      const DenseResidual& s = samples[i];
      if (std::abs(s.value) > gate) continue;
      const cv::Point& p = r.pixels1[i];
      const double w = 1.0 / (sigma * sigma);
      H.noalias() += s.J.transpose() * s.J * w;
      cells.add(p.x, p.y, s.J.transpose() * (s.value * w));
      const Eigen::Vector3d X_1 =
          level0.camera.backProject(Eigen::Vector2d(p.x, p.y), level0.depth1.at<float>(p));
      const Eigen::Vector3d X = R * X_1 + t;
      // The residual's derivative by the moved point is its Jacobian's translation part; cx and
      // cy errors in pixels of the full image's camera, whatever the level's resolution.
      b.noalias() +=
          s.J.transpose() * (calibrationResiduals(s.J.tail<3>(), R, t, X_1, X, camera) * w);
      // A mean: every 4th sample gives it to a few per cent at a quarter of the cost.
      if (pixels && (*used & 3) == 0) {
        const Eigen::Matrix<double, 2, 6> J = projectionJacobian(level0.camera, X);
        M.noalias() += J.transpose() * J;
        ++m_samples;
      }
      ++*used;
    }
  };
  accumulate(r.geometric, out.geometric_scale, false, &out.geometric_samples);
  const Matrix6 H_depth = H;
  const int depth_samples = out.geometric_samples;
  accumulate(r.photometric, out.photometric_sigma, true, &out.photometric_samples);
  const Matrix6 H_dense = H;
  const Eigen::Matrix<double, 6, 5> b_dense = b;
  const CellScores dense_cells = cells;
  PinholeCamera k = camera;
  k.distortion = {};
  for (const AlignmentFeature& f : features) {
    const Eigen::Vector3d X = T_21.map(f.X_1);
    if (!(X.z() > 0.05 && f.X_1.z() > 0.05)) continue;
    const Eigen::Vector2d residual = k.project(X) - f.uv_2;
    if (residual.norm() > o.feature_gate_px) continue;
    const Eigen::Matrix<double, 2, 6> J = projectionJacobian(k, X) / f.sigma_px;
    H.noalias() += J.transpose() * J;
    Eigen::Matrix<double, 2, 5> residuals;
    for (int row = 0; row < 2; ++row) {
      residuals.row(row) = calibrationResiduals(J.row(row).tail<3>(), R, t, f.X_1, X, camera);
    }
    b.noalias() += J.transpose() * residuals;
    const Eigen::Vector2d uv_1 = k.project(f.X_1);
    cells.add(uv_1.x(), uv_1.y(), J.transpose() * (residual / f.sigma_px));
    ++out.feature_samples;
  }
  out.cells = cells.used();

  // The resolution floor (header): the mean information of one sample, the colour's in pixels
  // of image motion at resolution_px, the depth's in its measured noise at depth_resolution.
  if (o.resolution_px > 0 && m_samples > 0 && depth_samples > 0) {
    const Matrix6 one_sample = M / (m_samples * o.resolution_px * o.resolution_px) +
                               H_depth / (depth_samples * o.depth_resolution * o.depth_resolution);
    if (!invertible(one_sample, &out.resolution_covariance)) out.resolution_covariance.setZero();
  }
  auto sandwich = [](const Matrix6& H_inv, const Matrix6& scatter, const Matrix6& H) {
    const Matrix6 C = H_inv * (scatter + H) * H_inv;
    return Matrix6(0.5 * (C + C.transpose()));
  };
  Matrix6 H_inv;
  if (invertible(H_dense, &H_inv)) {
    out.dense_step = -H_inv * dense_cells.total();
    out.dense_calibration_sensitivity = -H_inv * b_dense;
    out.dense_covariance =
        sandwich(H_inv, dense_cells.scatter(), H_dense) + out.resolution_covariance;
    out.dense_ok = out.dense_step.allFinite() && out.dense_covariance.allFinite() &&
                   out.dense_calibration_sensitivity.allFinite();
  }
  if (!invertible(H, &H_inv)) return out;
  out.residual_covariance = sandwich(H_inv, cells.scatter(), H);
  out.calibration_sensitivity = -H_inv * b;
  out.covariance = out.residual_covariance + out.resolution_covariance;
  out.information = out.covariance.inverse();
  out.covariance_ok = out.covariance.allFinite() && out.information.allFinite() &&
                      out.calibration_sensitivity.allFinite();
  return out;
}

}  // namespace pnpba
