#include "pnpba/pipeline/covariance_model.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>

namespace pnpba {

std::string CovarianceModelOptions::validate() const {
  if (!(min_variance_factor > 0) || !(max_variance_factor >= min_variance_factor) ||
      !std::isfinite(max_variance_factor)) {
    return "covariance model: variance factor bounds must satisfy 0 < min <= max < inf";
  }
  if (!(correlation_cell_px > 0)) return "covariance model: correlation cell must be > 0 px";
  if (!(duplicate_radius_px >= 0) || !std::isfinite(duplicate_radius_px)) {
    return "covariance model: duplicate radius must be finite and >= 0 px";
  }
  for (double s : {focal_sigma, principal_point_sigma_px, depth_scale_sigma, motion_sigma,
                   motion_cap_deg, motion_cap_m, slide_probe_m, slide_consistency_sigma}) {
    if (!(s >= 0) || !std::isfinite(s)) {
      return "covariance model: calibration sigmas, motion sigma, motion caps and slide term must "
             "be finite and >= 0";
    }
  }
  return "";
}

PoseSigmas poseSigmas(const Matrix6d& covariance) {
  return {std::sqrt(covariance.topLeftCorner<3, 3>().trace()) * 180.0 / M_PI,
          std::sqrt(covariance.bottomRightCorner<3, 3>().trace()) * 100.0};
}

namespace {

// motion_sigma * m, levelling off at cap (0: no cap): linear where it is well below the cap.
double motionSigma(double m, double cap, const CovarianceModelOptions& options) {
  const double linear = options.motion_sigma * m;
  if (!(cap > 0)) return linear;
  const double ratio = linear / cap;
  return linear / std::sqrt(1.0 + ratio * ratio);
}

}  // namespace

Matrix6d motionCovariance(const SE3Quat& T_21, const CovarianceModelOptions& options) {
  const double angle = T_21.log().head<3>().norm(), distance = T_21.translation().norm();
  const double rotation = motionSigma(angle, options.motion_cap_deg * M_PI / 180.0, options);
  const double translation = motionSigma(distance, options.motion_cap_m, options);
  Matrix6d C = Matrix6d::Zero();
  C.diagonal() << Eigen::Vector3d::Constant(rotation * rotation),
      Eigen::Vector3d::Constant(translation * translation);
  return C;
}

Eigen::Vector3d slideVarianceAbove(const Eigen::Vector3d& slide_sigma_m, const Matrix6d& nominal) {
  return (slide_sigma_m.cwiseAbs2() - nominal.bottomRightCorner<3, 3>().diagonal()).cwiseMax(0.0);
}

double varianceFactor(double chi2, int dof, const CovarianceModelOptions& options) {
  if (!options.scale_by_fit || dof <= 0 || !std::isfinite(chi2)) return 1.0;
  return std::clamp(chi2 / dof, options.min_variance_factor, options.max_variance_factor);
}

double pairChi2(const PointPair& pair, const SE3Quat& T_21, const PinholeCamera& camera,
                double pixel_sigma, double depth_noise_k) {
  const Eigen::Vector3d& X = pair.X_1;
  const Eigen::Vector3d Y = T_21.map(X);
  if (!(Y.z() > 0) || !(X.z() > 0)) return std::numeric_limits<double>::infinity();
  const Eigen::Vector2d e = camera.project(Y) - pair.uv_2;
  // Covariance of X from depth 1 (along the ray X / z) and image 1's pixel (across it).
  const double z = X.z(), sigma_z = depth_noise_k * z * z, s1 = pixel_sigma * pair.sigma_1;
  const Eigen::Vector3d ray = X / z;
  Eigen::Matrix3d cov_X = sigma_z * sigma_z * ray * ray.transpose();
  cov_X(0, 0) += s1 * s1 * z * z / (camera.fx * camera.fx);
  cov_X(1, 1) += s1 * s1 * z * z / (camera.fy * camera.fy);
  const double iz = 1.0 / Y.z();
  Eigen::Matrix<double, 2, 3> H;
  H << camera.fx * iz, 0, -camera.fx * Y.x() * iz * iz, 0, camera.fy * iz,
      -camera.fy * Y.y() * iz * iz;
  const Eigen::Matrix<double, 2, 3> J = H * T_21.rotation().toRotationMatrix();
  const double s2 = pixel_sigma * pair.sigma_2;
  const Eigen::Matrix2d cov_e = J * cov_X * J.transpose() + s2 * s2 * Eigen::Matrix2d::Identity();
  return e.dot(cov_e.ldlt().solve(e));
}

double pairDepthChi2(const PointPair& pair, const SE3Quat& T_21, double depth_noise_k) {
  const Eigen::Vector3d& X = pair.X_1;
  const Eigen::Vector3d Y = T_21.map(X);
  if (!(Y.z() > 0) || !(X.z() > 0) || !(pair.depth_2 > 0)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  // Depth 1's error moves X along its ray, which camera 2 sees as (R ray)_z of it in z.
  const double along = (T_21.rotation() * (X / X.z())).z();
  const double s1 = along * depth_noise_k * X.z() * X.z();
  const double s2 = depth_noise_k * pair.depth_2 * pair.depth_2;
  const double e = pair.depth_2 - Y.z();
  return e * e / (s1 * s1 + s2 * s2);
}

namespace {

// CDF of s * chi2(dof) at x, dof 1 or 2.
double scaledChi2Cdf(double x, double s, int dof) {
  return dof == 1 ? std::erf(std::sqrt(x / (2 * s))) : 1 - std::exp(-x / (2 * s));
}

}  // namespace

double robustVarianceFactor(const std::vector<double>& chi2, double gate,
                            const CovarianceModelOptions& options, int dof) {
  if (!options.scale_by_fit || !(gate > 0)) return 1.0;
  std::vector<double> below;
  for (double c : chi2)
    if (c < gate) below.push_back(c);
  if (below.size() < 10) return 1.0;
  auto mid = below.begin() + below.size() / 2;
  std::nth_element(below.begin(), mid, below.end());
  const double m = *mid;
  // The cut distribution's median m solves F(m) = F(gate) / 2 for chi2(dof) scaled by s;
  // F(m) / F(gate) falls as s grows, so bisect on log s.
  auto excess = [&](double s) {
    return scaledChi2Cdf(m, s, dof) - 0.5 * scaledChi2Cdf(gate, s, dof);
  };
  double lo = options.min_variance_factor, hi = options.max_variance_factor;
  if (excess(lo) <= 0) return lo;
  if (excess(hi) >= 0) return hi;
  for (int i = 0; i < 60; ++i) {
    const double s = std::sqrt(lo * hi);
    (excess(s) > 0 ? lo : hi) = s;
  }
  return std::sqrt(lo * hi);
}

double correlationInflation(const std::vector<Eigen::Vector2d>& pixels,
                            const std::vector<Eigen::Vector2d>& whitened, double cell_px) {
  std::map<std::pair<int, int>, std::vector<size_t>> cells;
  for (size_t i = 0; i < pixels.size(); ++i) {
    cells[{static_cast<int>(std::floor(pixels[i].x() / cell_px)),
           static_cast<int>(std::floor(pixels[i].y() / cell_px))}]
        .push_back(i);
  }
  double cross = 0, own = 0;
  size_t in_shared = 0;
  for (const auto& [cell, members] : cells) {
    if (members.size() < 2) continue;
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    double squares = 0;
    for (size_t i : members) {
      sum += whitened[i];
      squares += whitened[i].squaredNorm();
    }
    cross += sum.squaredNorm() - squares;  // sum over i != j of e_i . e_j
    own += (members.size() - 1) * squares;
    in_shared += members.size();
  }
  if (cells.empty() || own <= 0) return 1.0;
  const double rho = std::clamp(cross / own, 0.0, 1.0);
  const double m = static_cast<double>(pixels.size()) / cells.size();
  return std::max(1.0, 1.0 + (m - 1) * rho);
}

double duplicateInflation(const std::vector<Eigen::Vector2d>& pixels_1,
                          const std::vector<Eigen::Vector2d>& pixels_2, double radius_px) {
  const size_t n = std::min(pixels_1.size(), pixels_2.size());
  if (n == 0 || !(radius_px > 0)) return 1.0;
  // Image-2 cells of the radius's size, laid out by counting sort: a twin lies in the same or
  // a neighbouring cell.
  Eigen::Vector2d lo = pixels_2[0], hi = pixels_2[0];
  for (size_t i = 1; i < n; ++i) lo = lo.cwiseMin(pixels_2[i]), hi = hi.cwiseMax(pixels_2[i]);
  if (!lo.allFinite() || !hi.allFinite()) return 1.0;
  const double cells_wide = std::floor((hi.x() - lo.x()) / radius_px) + 1;
  const double cells_high = std::floor((hi.y() - lo.y()) / radius_px) + 1;
  if (cells_wide * cells_high > 16.0 * 1024 * 1024) return 1.0;  // a degenerate spread
  const int width = static_cast<int>(cells_wide), height = static_cast<int>(cells_high);
  std::vector<int> cell(n), start(static_cast<size_t>(width) * height + 1, 0), order(n);
  for (size_t i = 0; i < n; ++i) {
    const int cx = static_cast<int>((pixels_2[i].x() - lo.x()) / radius_px);
    const int cy = static_cast<int>((pixels_2[i].y() - lo.y()) / radius_px);
    cell[i] = cy * width + cx;
    ++start[cell[i] + 1];
  }
  for (size_t c = 1; c < start.size(); ++c) start[c] += start[c - 1];
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (size_t i = 0; i < n; ++i) order[fill[cell[i]]++] = static_cast<int>(i);

  std::vector<size_t> parent(n);
  for (size_t i = 0; i < n; ++i) parent[i] = i;
  auto root = [&parent](size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  const double r2 = radius_px * radius_px;
  size_t groups = n;
  for (size_t i = 0; i < n; ++i) {
    const int cx = cell[i] % width, cy = cell[i] / width;
    for (int y = std::max(cy - 1, 0); y <= std::min(cy + 1, height - 1); ++y) {
      for (int x = std::max(cx - 1, 0); x <= std::min(cx + 1, width - 1); ++x) {
        const int c = y * width + x;
        for (int k = start[c]; k < start[c + 1]; ++k) {
          const size_t j = static_cast<size_t>(order[k]);
          if (j <= i || (pixels_2[i] - pixels_2[j]).squaredNorm() >= r2 ||
              (pixels_1[i] - pixels_1[j]).squaredNorm() >= r2) {
            continue;
          }
          const size_t a = root(i), b = root(j);
          if (a != b) parent[a] = b, --groups;
        }
      }
    }
  }
  return static_cast<double>(n) / groups;
}

Eigen::Matrix<double, 1, 5> calibrationResiduals(const Eigen::RowVector3d& D,
                                                 const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                                 const Eigen::Vector3d& X_1,
                                                 const Eigen::Vector3d& Y,
                                                 const PinholeCamera& camera) {
  // D m_k with the warps' few nonzero entries written out (the dense evidence takes one per
  // sample): dA_fx = diag(-1, 0, 0), dA_fy = diag(0, -1, 0), dA_cx has -1 / fx at (0, 2), dA_cy
  // -1 / fy at (1, 2), dA_scale = I (its m is R X_1 - Y = -t).
  const double along_x = D.dot(R.col(0)), along_y = D.dot(R.col(1));
  Eigen::Matrix<double, 1, 5> r;
  r << -X_1.x() * along_x + D.x() * Y.x(), -X_1.y() * along_y + D.y() * Y.y(),
      (-X_1.z() * along_x + D.x() * Y.z()) / camera.fx,
      (-X_1.z() * along_y + D.y() * Y.z()) / camera.fy, -D.dot(t);
  return r;
}

Eigen::Matrix<double, 6, 5> calibrationSensitivity(const std::vector<CalibrationPoint>& points,
                                                   const SE3Quat& T_21, const PinholeCamera& camera,
                                                   double depth_noise_k, CalibrationMetric metric) {
  const Eigen::Matrix3d R = T_21.rotation().toRotationMatrix();
  const Eigen::Vector3d t = T_21.translation();
  Matrix6d N = Matrix6d::Zero();
  Eigen::Matrix<double, 6, 5> b = Eigen::Matrix<double, 6, 5>::Zero();
  int used = 0;
  for (const CalibrationPoint& p : points) {
    const Eigen::Vector3d Y = T_21.map(p.X_1);
    if (!(Y.z() > 0.05) || !(p.X_1.z() > 0)) continue;
    // What the estimator observes of Y: its pixel (u, v) and, with depth 2, its z.
    const double iz = 1.0 / Y.z();
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    H.row(0) << camera.fx * iz, 0, -camera.fx * Y.x() * iz * iz;
    H.row(1) << 0, camera.fy * iz, -camera.fy * Y.y() * iz * iz;
    Eigen::Vector3d w;
    w.head<2>().setConstant(1.0 / (p.sigma_px * p.sigma_px));
    const double sigma_z = std::max(depth_noise_k * Y.z() * Y.z(), 1e-4);
    if (p.has_depth_2) H(2, 2) = 1;
    w(2) = p.has_depth_2 ? 1.0 / (sigma_z * sigma_z) : 0.0;
    if (metric == CalibrationMetric::kPoints) {  // kDense: as kReprojection here
      H.setIdentity();
      w.setConstant(1.0 / (sigma_z * sigma_z));
    }
    Eigen::Matrix<double, 3, 6> dY;  // d(exp(d) Y)/dd
    dY << -skew(Y), Eigen::Matrix3d::Identity();
    const Eigen::Matrix<double, 3, 6> J = H * dY;
    N.noalias() += J.transpose() * w.asDiagonal() * J;
    Eigen::Matrix<double, 3, 5> residuals;  // per unit error, of each observation of Y
    for (int row = 0; row < 3; ++row) {
      residuals.row(row) = calibrationResiduals(H.row(row), R, t, p.X_1, Y, camera);
    }
    b.noalias() += J.transpose() * w.asDiagonal() * residuals;
    ++used;
  }
  if (used < 3) return Eigen::Matrix<double, 6, 5>::Zero();
  // The shift minimises the weighted residual (calibration residuals + H dY d): d = -N^-1 b.
  // A direction the points leave free takes no shift (its information's own covariance already
  // says so).
  Eigen::SelfAdjointEigenSolver<Matrix6d> eig(N);
  const Eigen::Matrix<double, 6, 1> lambda = eig.eigenvalues();
  Eigen::Matrix<double, 6, 1> inverse;
  for (int i = 0; i < 6; ++i) inverse(i) = lambda(i) > 1e-9 * lambda(5) ? 1.0 / lambda(i) : 0.0;
  return -eig.eigenvectors() * inverse.asDiagonal() * eig.eigenvectors().transpose() * b;
}

Matrix6d calibrationCovariance(const std::vector<CalibrationPoint>& points, const SE3Quat& T_21,
                               const PinholeCamera& camera, double depth_noise_k,
                               const CovarianceModelOptions& options, CalibrationMetric metric) {
  return calibrationCovariance(calibrationSensitivity(points, T_21, camera, depth_noise_k, metric),
                               T_21, options, metric);
}

Matrix6d calibrationCovariance(const Eigen::Matrix<double, 6, 5>& g, const SE3Quat& T_21,
                               const CovarianceModelOptions& options, CalibrationMetric metric) {
  Eigen::Matrix<double, 5, 1> sigma;
  sigma << options.focal_sigma, options.focal_sigma, options.principal_point_sigma_px,
      options.principal_point_sigma_px, options.depth_scale_sigma;
  Matrix6d C = g * sigma.cwiseAbs2().asDiagonal() * g.transpose();
  if (metric == CalibrationMetric::kDense) {
    // fx scales the rotation about the image's y axis, fy about its x axis.
    const Eigen::Vector3d w = T_21.log().head<3>();
    const double f2 = options.focal_sigma * options.focal_sigma;
    C(0, 0) += f2 * w.x() * w.x();
    C(1, 1) += f2 * w.y() * w.y();
  }
  return C;
}

}  // namespace pnpba
