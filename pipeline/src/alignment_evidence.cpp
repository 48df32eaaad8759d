#include "pnpba/pipeline/alignment_evidence.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <numeric>

#include "rgbd_residuals.h"

namespace pnpba {

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  auto mid = v.begin() + v.size() / 2;
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

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

}  // namespace

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

  // A brightness offset between the frames (auto exposure) is not pose error.
  std::vector<double> values;
  for (const DenseResidual& s : r.photometric) values.push_back(s.value);
  const double bias = median(values);
  for (DenseResidual& s : r.photometric) s.value -= bias;
  out.geometric_scale = robustSigma(r.geometric, 0.1);
  out.photometric_sigma = robustSigma(r.photometric, 1.0);
  out.photometric_agreement = correlation(r.intensity1, r.intensity2);

  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  auto accumulate = [&](const std::vector<DenseResidual>& samples, double sigma, int* used) {
    const double gate = o.gate_sigmas * sigma;
    for (const DenseResidual& s : samples) {
      if (std::abs(s.value) > gate) continue;
      H.noalias() += s.J.transpose() * s.J / (sigma * sigma);
      ++*used;
    }
  };
  accumulate(r.geometric, out.geometric_scale, &out.geometric_samples);
  accumulate(r.photometric, out.photometric_sigma, &out.photometric_samples);
  out.information = H / o.correlated_samples;
  PinholeCamera k = camera;
  k.distortion = {};
  for (const AlignmentFeature& f : features) {
    const Eigen::Vector3d X = T_21.map(f.X_1);
    if (!(X.z() > 0.05) || (k.project(X) - f.uv_2).norm() > o.feature_gate_px) continue;
    const Eigen::Matrix<double, 2, 6> J = projectionJacobian(k, X) / f.sigma_px;
    out.information.noalias() += J.transpose() * J;
    ++out.feature_samples;
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(out.information);
  if (eig.info() == Eigen::Success && eig.eigenvalues()(0) > 0 &&
      eig.eigenvalues()(0) > 1e-12 * eig.eigenvalues()(5)) {
    out.covariance = o.variance_factor * eig.eigenvectors() *
                     eig.eigenvalues().cwiseInverse().asDiagonal() * eig.eigenvectors().transpose();
    out.covariance_ok = out.covariance.allFinite();
  }
  return out;
}

}  // namespace pnpba
