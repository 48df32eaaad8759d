#include "pnpba/optimize/pose_only.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

#include "huber.h"
#include "lm_damping.h"
#include "pnpba/optimize/projection_jacobians.h"

namespace pnpba {

int PoseOnlyProblem::numActive() const {
  return static_cast<int>(std::count(active.begin(), active.end(), 1));
}

namespace {

Eigen::Vector2d errorAt(const PoseOnlyProblem& p, size_t i, const Eigen::Vector3d& P) {
  return p.pixels[i] - p.camera.project(P);
}

double chi2Of(const Eigen::Vector2d& e, double w) {
  return e.dot((w * Eigen::Matrix2d::Identity()) * e);
}

// H = sum J' W J and b = -sum J' W e over the active observations at T (W = rho' w I).
// T as a rotation matrix and a translation, computed once per pass over the observations.
struct Motion {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  explicit Motion(const SE3Quat& T) : R(T.rotation().toRotationMatrix()), t(T.translation()) {}
  Eigen::Vector3d map(const Eigen::Vector3d& X) const { return R * X + t; }
};

// The error's rows by the left perturbation [rotation; translation] at P = (x, y, z) written
// out: row 1 is (fx u v, -fx (1 + u^2), fx v, -fx / z, 0, fx u / z) and row 2 is
// (fy (1 + v^2), -fy u v, -fy u, 0, -fy / z, fy v / z), u = x / z, v = y / z: the same as
// pinholeErrorByPoint(P) [-[P]x, I] to round-off, with its two zeros known. H's upper triangle
// (21 sums) and b are summed in locals and H mirrored once at the end, where the 6 x 6 product
// formed all 36 sums per observation (with the chi2 passes below: 185.5 k -> 154.8 k
// instructions per BM_PoseOnlyArrays solve).
void linearize(const PoseOnlyProblem& p, const SE3Quat& T, Matrix6d* H, Vector6d* b) {
  double h[21] = {};
  double g[6] = {};
  const Motion M(T);
  const double fx = p.camera.fx, fy = p.camera.fy;
  for (size_t i = 0; i < p.size(); ++i) {
    if (!p.active[i]) continue;
    const Eigen::Vector3d P = M.map(p.points[i]);
    const Eigen::Vector2d e = errorAt(p, i, P);
    const double iz = 1.0 / P.z(), u = P.x() * iz, v = P.y() * iz;
    const double a[6] = {fx * u * v, -fx * (1 + u * u), fx * v, -fx * iz, 0.0, fx * u * iz};
    const double c[6] = {fy * (1 + v * v), -fy * u * v, -fy * u, 0.0, -fy * iz, fy * v * iz};
    const double w = p.information[i];
    const double rw = internal::huberWeight(chi2Of(e, w), p.huber_delta) * w;
    int k = 0;
#pragma GCC unroll 6
    for (int r = 0; r < 6; ++r) {
      const double ar = rw * a[r], cr = rw * c[r];
#pragma GCC unroll 6
      for (int s = r; s < 6; ++s) h[k++] += ar * a[s] + cr * c[s];
      g[r] -= ar * e.x() + cr * e.y();
    }
  }
  int k = 0;
  for (int r = 0; r < 6; ++r) {
    for (int s = r; s < 6; ++s, ++k) (*H)(r, s) = (*H)(s, r) = h[k];
    (*b)(r) = g[r];
  }
}

// The damped step (H + lambda I) x = b; false when the factorisation or the step fails.
bool solveDamped(const Matrix6d& H, const Vector6d& b, double lambda, Vector6d* x) {
  Matrix6d S = H;
  S.diagonal().array() += lambda;
  const Eigen::LLT<Matrix6d> llt(S);
  if (llt.info() != Eigen::Success) return false;
  *x = llt.solve(b);
  return x->allFinite();
}

}  // namespace

double poseOnlyChi2(const PoseOnlyProblem& p, size_t i, const SE3Quat& T) {
  return chi2Of(errorAt(p, i, T.map(p.points[i])), p.information[i]);
}

bool poseOnlyDepthPositive(const PoseOnlyProblem& p, size_t i, const SE3Quat& T) {
  return T.map(p.points[i]).z() > 0.0;
}

double poseOnlyRobustChi2(const PoseOnlyProblem& p, const SE3Quat& T) {
  const Motion M(T);
  double chi2 = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    if (!p.active[i]) continue;
    chi2 += internal::huberCost(chi2Of(errorAt(p, i, M.map(p.points[i])), p.information[i]),
                                p.huber_delta);
  }
  return chi2;
}

int optimizePoseOnly(const PoseOnlyProblem& p, SE3Quat* T, int iterations,
                     const OptimizerOptions& options) {
  if (iterations <= 0 || p.numActive() == 0) return 0;
  const double initial_chi2 = poseOnlyRobustChi2(p, *T);
  const double min_predicted = options.min_relative_predicted_decrease * initial_chi2;
  internal::ConvergenceByDecrease convergence(options.min_relative_accepted_decrease *
                                              initial_chi2);
  // chi2 at *T throughout: a rejected step restores *T, whose chi2 g2o would compute again.
  double current_chi2 = initial_chi2, lambda = 0, nu = 2;
  Matrix6d H;
  Vector6d b, x;
  auto predicted = [&](double l) { return x.dot(l * x + b); };
  int done = 0;
  for (int it = 0; it < iterations; ++it) {
    ++done;
    linearize(p, *T, &H, &b);
    if (it == 0) {
      lambda = options.user_lambda_init > 0 ? options.user_lambda_init
                                            : options.tau * H.diagonal().cwiseAbs().maxCoeff();
      nu = 2;
    }
    double rho = 0;
    bool converged = false;
    int trials = 0;
    bool stop = false;
    do {
      const bool ok = solveDamped(H, b, lambda, &x);
      if (ok && trials == 0 && predicted(lambda) < min_predicted) {
        stop = converged = true;  // nothing representable left to gain; T untouched
        break;
      }
      const SE3Quat before = *T;
      if (ok) *T = SE3Quat::exp(x) * *T;
      const double new_chi2 = ok ? poseOnlyRobustChi2(p, *T) : std::numeric_limits<double>::max();
      const double scale = ok ? predicted(lambda) + 1e-3 : 1.0;
      rho = (current_chi2 - new_chi2) / scale;
      if (rho > 0 && std::isfinite(new_chi2)) {
        lambda = internal::acceptedStepLambda(lambda, rho);
        nu = 2;
        converged = convergence.convergedAfter(current_chi2 - new_chi2);
        current_chi2 = new_chi2;
      } else {
        lambda *= nu;
        nu *= 2;
        *T = before;
        if (!std::isfinite(lambda)) break;
      }
      ++trials;
    } while (rho < 0 && trials < options.max_trials_after_failure);
    if (stop || converged) break;
    if (trials == options.max_trials_after_failure || rho == 0 || !std::isfinite(lambda)) break;
  }
  return done;
}

bool poseOnlyCovariance(const PoseOnlyProblem& p, const SE3Quat& T, Matrix6d* covariance) {
  if (p.numActive() == 0) return false;
  Matrix6d H;
  Vector6d b;
  linearize(p, T, &H, &b);
  const Eigen::LLT<Matrix6d> llt(H);
  if (llt.info() != Eigen::Success || !llt.solve(b).allFinite()) return false;
  const Vector6d d = llt.matrixLLT().diagonal();
  if (!(d.minCoeff() > 1e-12 * d.maxCoeff())) return false;
  *covariance = llt.solve(Matrix6d::Identity());
  return covariance->allFinite();
}

}  // namespace pnpba
