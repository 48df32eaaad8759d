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

using internal::pinholeErrorByPoint;

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

void linearize(const PoseOnlyProblem& p, const SE3Quat& T, Matrix6d* H, Vector6d* b) {
  H->setZero();
  b->setZero();
  const Motion M(T);
  for (size_t i = 0; i < p.size(); ++i) {
    if (!p.active[i]) continue;
    const Eigen::Vector3d P = M.map(p.points[i]);
    const Eigen::Vector2d e = errorAt(p, i, P);
    const Eigen::Matrix<double, 2, 3> J_P = pinholeErrorByPoint(P, p.camera.fx, p.camera.fy);
    Eigen::Matrix<double, 2, 6> J;
    for (int r = 0; r < 2; ++r) {
      const Eigen::Vector3d a = J_P.row(r).transpose();
      J.row(r) << P.cross(a).transpose(), a.transpose();
    }
    const double w = p.information[i];
    const double rw = internal::huberWeight(chi2Of(e, w), p.huber_delta);
    const Eigen::Matrix<double, 6, 2> JtW = (rw * w) * J.transpose();
    H->noalias() += JtW * J;
    b->noalias() -= JtW * e;
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
  const double min_accepted = options.min_relative_accepted_decrease * initial_chi2;
  double current_chi2 = 0, lambda = 0, nu = 2;
  bool errors_current = false;
  Matrix6d H;
  Vector6d b, x;
  auto predicted = [&](double l) { return x.dot(l * x + b); };
  int done = 0;
  for (int it = 0; it < iterations; ++it) {
    ++done;
    if (it == 0 || !errors_current) current_chi2 = poseOnlyRobustChi2(p, *T);
    errors_current = true;
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
        converged = current_chi2 - new_chi2 < min_accepted;
        current_chi2 = new_chi2;
        errors_current = true;
      } else {
        lambda *= nu;
        nu *= 2;
        *T = before;
        errors_current = false;
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
