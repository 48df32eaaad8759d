#include "pnpba/pipeline/epnp.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace pnpba {

namespace {

using Matrix12d = Eigen::Matrix<double, 12, 12>;
using Vector12d = Eigen::Matrix<double, 12, 1>;
using Matrix6x10d = Eigen::Matrix<double, 6, 10>;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using Betas = Eigen::Vector4d;

// The six pairs of the four control points, in the order of the distance constraints.
constexpr std::array<std::array<int, 2>, 6> kControlPairs = {
    {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};

struct Problem {
  const Correspondences& pairs;
  const int* subset;
  int count;
  const PinholeCamera& camera;
  const Eigen::Vector3d& X(int i) const { return pairs[subset[i]].X_1; }
  const Eigen::Vector2d& uv(int i) const { return pairs[subset[i]].uv_2; }
};

// Control points in camera 1: the centroid and one step along each principal axis, scaled by
// the points' spread along it (largest first), away from the camera.
bool controlPoints(const Problem& p, std::array<Eigen::Vector3d, 4>* c) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int i = 0; i < p.count; ++i) centroid += p.X(i);
  centroid /= p.count;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (int i = 0; i < p.count; ++i) {
    const Eigen::Vector3d d = p.X(i) - centroid;
    scatter.noalias() += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> axes(scatter);
  if (axes.info() != Eigen::Success) return false;
  (*c)[0] = centroid;
  for (int k = 0; k < 3; ++k) {
    const int axis = 2 - k;  // eigenvalues ascend
    const double spread = std::sqrt(std::max(0.0, axes.eigenvalues()(axis)) / p.count);
    // The axes' signs are the eigen-solver's; under noise EPnP's pose depends on them. Pointing
    // each away from camera 1 keeps a flat scene's out-of-plane control point behind the wall:
    // the other way its median error (75 points on a plane, 1 px) is twice OpenCV's.
    Eigen::Vector3d axis_direction = axes.eigenvectors().col(axis);
    if (axis_direction.dot(centroid) < 0) axis_direction = -axis_direction;
    (*c)[k + 1] = centroid + spread * axis_direction;
  }
  return true;
}

// Each point's barycentric coordinates in the control points (they sum to 1). The basis is
// inverted through its SVD so that a nearly planar sample (a flat wall) still gets coordinates,
// as OpenCV's does.
void barycentric(const Problem& p, const std::array<Eigen::Vector3d, 4>& c,
                 std::vector<Eigen::Vector4d>* alphas) {
  Eigen::Matrix3d basis;
  for (int k = 0; k < 3; ++k) basis.col(k) = c[k + 1] - c[0];
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(basis, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d s = svd.singularValues();
  Eigen::Vector3d s_inv;
  for (int k = 0; k < 3; ++k) {
    s_inv(k) = s(k) > std::numeric_limits<double>::epsilon() * s(0) ? 1.0 / s(k) : 0.0;
  }
  const Eigen::Matrix3d inverse = svd.matrixV() * s_inv.asDiagonal() * svd.matrixU().transpose();
  alphas->resize(p.count);
  for (int i = 0; i < p.count; ++i) {
    const Eigen::Vector3d a = inverse * (p.X(i) - c[0]);
    (*alphas)[i] << 1.0 - a.sum(), a;
  }
}

// M^T M of the 2n x 12 system M x = 0 in the control points' camera-2 coordinates x.
Matrix12d normalMatrix(const Problem& p, const std::vector<Eigen::Vector4d>& alphas) {
  Matrix12d mtm = Matrix12d::Zero();
  const PinholeCamera& k = p.camera;
  for (int i = 0; i < p.count; ++i) {
    Vector12d row_u, row_v;
    for (int j = 0; j < 4; ++j) {
      const double a = alphas[i](j);
      row_u.segment<3>(3 * j) << a * k.fx, 0.0, a * (k.cx - p.uv(i).x());
      row_v.segment<3>(3 * j) << 0.0, a * k.fy, a * (k.cy - p.uv(i).y());
    }
    mtm.noalias() += row_u * row_u.transpose();
    mtm.noalias() += row_v * row_v.transpose();
  }
  return mtm;
}

// The distance constraints: row (a, b) of L times the ten products of the betas
// (b00, b01, b11, b02, b12, b22, b03, b13, b23, b33) gives |x_a - x_b|^2 for
// x = sum_k beta_k v_k.
Matrix6x10d distanceSystem(const std::array<Vector12d, 4>& v) {
  Matrix6x10d L;
  for (int r = 0; r < 6; ++r) {
    const auto [a, b] = kControlPairs[r];
    std::array<Eigen::Vector3d, 4> d;
    for (int k = 0; k < 4; ++k) d[k] = v[k].segment<3>(3 * a) - v[k].segment<3>(3 * b);
    L.row(r) << d[0].dot(d[0]), 2 * d[0].dot(d[1]), d[1].dot(d[1]), 2 * d[0].dot(d[2]),
        2 * d[1].dot(d[2]), d[2].dot(d[2]), 2 * d[0].dot(d[3]), 2 * d[1].dot(d[3]),
        2 * d[2].dot(d[3]), d[3].dot(d[3]);
  }
  return L;
}

// Least squares on the six distance constraints through the normal equations: N <= 5 unknowns,
// a fraction of a QR's or an SVD's work, and what RANSAC pays on every sample.
template <int N>
Eigen::Matrix<double, N, 1> leastSquares(const Eigen::Matrix<double, 6, N>& A, const Vector6d& b) {
  const Eigen::Matrix<double, N, N> normal = A.transpose() * A;
  return normal.ldlt().solve(A.transpose() * b);
}

// First guesses of the betas from the products the linearised constraints solve for, with
// one, two or three null vectors (the paper's N = 1, 2, 3 cases, in OpenCV's form).
Betas betasFromFour(const Matrix6x10d& L, const Vector6d& rho) {
  Eigen::Matrix<double, 6, 4> A;
  A << L.col(0), L.col(1), L.col(3), L.col(6);  // b00, b01, b02, b03
  const Eigen::Vector4d B = leastSquares<4>(A, rho);
  const double b0 = std::sqrt(std::abs(B(0)));
  const double sign = B(0) < 0 ? -1.0 : 1.0;
  return {b0, sign * B(1) / b0, sign * B(2) / b0, sign * B(3) / b0};
}

// beta_0 and beta_1 from the products b00, b01 and b11 (sign from b01; b11 of the wrong sign,
// which noise can give, read as 0).
Betas firstTwoBetas(double b00, double b01, double b11) {
  Betas betas = Betas::Zero();
  if (b00 < 0) {
    betas(0) = std::sqrt(-b00);
    betas(1) = b11 < 0 ? std::sqrt(-b11) : 0.0;
  } else {
    betas(0) = std::sqrt(b00);
    betas(1) = b11 > 0 ? std::sqrt(b11) : 0.0;
  }
  if (b01 < 0) betas(0) = -betas(0);
  return betas;
}

Betas betasFromTwo(const Matrix6x10d& L, const Vector6d& rho) {
  const Eigen::Vector3d B = leastSquares<3>(L.leftCols<3>(), rho);  // b00, b01, b11
  return firstTwoBetas(B(0), B(1), B(2));
}

Betas betasFromThree(const Matrix6x10d& L, const Vector6d& rho) {
  // b00, b01, b11, b02, b12
  const Eigen::Matrix<double, 5, 1> B = leastSquares<5>(L.leftCols<5>(), rho);
  Betas betas = firstTwoBetas(B(0), B(1), B(2));
  betas(2) = B(3) / betas(0);
  return betas;
}

// Five Gauss-Newton steps on the six distance constraints.
void refineBetas(const Matrix6x10d& L, const Vector6d& rho, Betas* betas) {
  for (int iteration = 0; iteration < 5; ++iteration) {
    const Betas& b = *betas;
    Eigen::Matrix<double, 6, 4> J;
    Vector6d residual;
    for (int r = 0; r < 6; ++r) {
      const auto l = L.row(r);
      J.row(r) << 2 * l(0) * b(0) + l(1) * b(1) + l(3) * b(2) + l(6) * b(3),
          l(1) * b(0) + 2 * l(2) * b(1) + l(4) * b(2) + l(7) * b(3),
          l(3) * b(0) + l(4) * b(1) + 2 * l(5) * b(2) + l(8) * b(3),
          l(6) * b(0) + l(7) * b(1) + l(8) * b(2) + 2 * l(9) * b(3);
      residual(r) = rho(r) - (l(0) * b(0) * b(0) + l(1) * b(0) * b(1) + l(2) * b(1) * b(1) +
                              l(3) * b(0) * b(2) + l(4) * b(1) * b(2) + l(5) * b(2) * b(2) +
                              l(6) * b(0) * b(3) + l(7) * b(1) * b(3) + l(8) * b(2) * b(3) +
                              l(9) * b(3) * b(3));
    }
    *betas += leastSquares<4>(J, residual);
  }
}

struct Candidate {
  SE3Quat T;
  double error = std::numeric_limits<double>::infinity();  // mean reprojection error, px
};

// The pose the betas give: the control points in camera 2, every point from its barycentric
// coordinates (in front of the camera: the null vectors' sign is free), and the rigid motion
// that best maps camera 1's points onto them (Procrustes).
Candidate poseFromBetas(const Problem& p, const std::vector<Eigen::Vector4d>& alphas,
                        const std::array<Vector12d, 4>& v, const Betas& betas) {
  Vector12d x = Vector12d::Zero();
  for (int k = 0; k < 4; ++k) x += betas(k) * v[k];
  std::vector<Eigen::Vector3d> P(p.count);
  for (int i = 0; i < p.count; ++i) {
    P[i] = alphas[i](0) * x.segment<3>(0) + alphas[i](1) * x.segment<3>(3) +
           alphas[i](2) * x.segment<3>(6) + alphas[i](3) * x.segment<3>(9);
  }
  if (P[0].z() < 0) {
    for (Eigen::Vector3d& q : P) q = -q;
  }
  Eigen::Vector3d centroid_2 = Eigen::Vector3d::Zero(), centroid_1 = Eigen::Vector3d::Zero();
  for (int i = 0; i < p.count; ++i) centroid_2 += P[i], centroid_1 += p.X(i);
  centroid_2 /= p.count;
  centroid_1 /= p.count;
  Eigen::Matrix3d cross = Eigen::Matrix3d::Zero();
  for (int i = 0; i < p.count; ++i) {
    cross.noalias() += (P[i] - centroid_2) * (p.X(i) - centroid_1).transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cross, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
  if (R.determinant() < 0) R.row(2) = -R.row(2);  // a reflection: OpenCV's correction
  const Eigen::Vector3d t = centroid_2 - R * centroid_1;
  Candidate c;
  if (!R.allFinite() || !t.allFinite()) return c;
  c.T = SE3Quat(R, t);
  double sum = 0;
  const PinholeCamera& k = p.camera;
  for (int i = 0; i < p.count; ++i) {
    const Eigen::Vector3d Q = R * p.X(i) + t;
    const Eigen::Vector2d uv(k.cx + k.fx * Q.x() / Q.z(), k.cy + k.fy * Q.y() / Q.z());
    sum += (uv - p.uv(i)).norm();
  }
  c.error = sum / p.count;
  if (!std::isfinite(c.error)) c.error = std::numeric_limits<double>::infinity();
  return c;
}

}  // namespace

bool solveEpnp(const Correspondences& pairs, const int* subset, int count,
               const PinholeCamera& camera, SE3Quat* T_21) {
  if (count < 4) return false;
  const Problem p{pairs, subset, count, camera};
  std::array<Eigen::Vector3d, 4> c;
  if (!controlPoints(p, &c)) return false;
  std::vector<Eigen::Vector4d> alphas;
  barycentric(p, c, &alphas);

  const Eigen::SelfAdjointEigenSolver<Matrix12d> null_space(normalMatrix(p, alphas));
  if (null_space.info() != Eigen::Success) return false;
  std::array<Vector12d, 4> v;  // the four smallest eigenvalues' vectors, smallest first
  for (int k = 0; k < 4; ++k) v[k] = null_space.eigenvectors().col(k);

  const Matrix6x10d L = distanceSystem(v);
  Vector6d rho;
  for (int r = 0; r < 6; ++r) {
    rho(r) = (c[kControlPairs[r][0]] - c[kControlPairs[r][1]]).squaredNorm();
  }
  Candidate best;
  for (Betas (*guess)(const Matrix6x10d&, const Vector6d&) :
       {&betasFromFour, &betasFromTwo, &betasFromThree}) {
    Betas betas = guess(L, rho);
    refineBetas(L, rho, &betas);
    if (!betas.allFinite()) continue;
    const Candidate candidate = poseFromBetas(p, alphas, v, betas);
    if (candidate.error < best.error) best = candidate;
  }
  if (!std::isfinite(best.error)) return false;
  *T_21 = best.T;
  return true;
}

}  // namespace pnpba
