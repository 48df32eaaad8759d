#include "pnpba/optimize/rgbd_pair.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "huber.h"
#include "lm_damping.h"
#include "pnpba/core/error.h"
#include "pnpba/optimize/projection_jacobians.h"

namespace pnpba {

int RgbdPairProblem::degreesOfFreedom() const {
  if (observations.empty()) return 0;  // as the graph, whose pose no edge reaches is not active
  int dof = -6;                        // the pose
  for (const RgbdPairObservation& o : observations) {
    dof += 3 + (o.depth2 ? 3 : 2) - 3;  // camera 1's errors and camera 2's, less the point
  }
  return dof;
}

namespace {

using Matrix63 = Eigen::Matrix<double, 6, 3>;
using internal::huberCost;
using internal::huberWeight;

// The normal equations of one linearisation, points not yet eliminated: the pose's block and
// right-hand side, and per point its own block, right-hand side and pose-point block.
struct PointBlocks {
  Eigen::Matrix3d H;
  Eigen::Vector3d b;
  Matrix63 H_pose_point;
};
struct NormalEquations {
  Matrix6d H_pose;
  Vector6d b_pose;
  std::vector<PointBlocks> points;
  double robust_chi2 = 0;
};

// Camera 2's error at P = T X and its Jacobians by the pose tangent and by X (R: T's rotation):
// added to the pose's blocks and written as the point's, with the weight rho' Omega; returns
// the error's robust chi2.
template <int D>
double addCamera2(const Eigen::Matrix<double, D, 1>& e, const Eigen::Matrix<double, D, 3>& J_P,
                  const Eigen::Vector3d& P, const Eigen::Matrix3d& R,
                  const Eigen::Matrix<double, D, D>& information, double delta, NormalEquations* n,
                  PointBlocks* point) {
  const double chi2 = e.dot(information * e);
  Eigen::Matrix<double, D, 6> J_pose;
  for (int r = 0; r < D; ++r) {
    const Eigen::Vector3d a = J_P.row(r).transpose();
    J_pose.row(r) << P.cross(a).transpose(), a.transpose();
  }
  const Eigen::Matrix<double, D, 3> J_point = J_P * R;
  const Eigen::Matrix<double, D, D> W = huberWeight(chi2, delta) * information;
  const Eigen::Matrix<double, 6, D> JpW = J_pose.transpose() * W;
  const Eigen::Matrix<double, 3, D> JlW = J_point.transpose() * W;
  n->H_pose.noalias() += JpW * J_pose;
  n->b_pose.noalias() -= JpW * e;
  // The point's first error: its blocks are written, not added to (no zeroing pass).
  point->H.noalias() = JlW * J_point;
  point->b.noalias() = -JlW * e;
  point->H_pose_point.noalias() = JpW * J_point;
  return huberCost(chi2, delta);
}

// Linearises every error at the estimate (camera 2's then camera 1's per point, the graph's edge
// order) into *n.
void linearize(const RgbdPairProblem& p, const RgbdPairEstimate& x, NormalEquations* n) {
  const StereoIntrinsics& k = p.camera;
  const Eigen::Matrix3d R = x.T_21.rotation().toRotationMatrix();
  const Eigen::Vector3d& t = x.T_21.translation();
  n->H_pose.setZero();
  n->b_pose.setZero();
  n->points.resize(p.observations.size());
  n->robust_chi2 = 0;
  for (size_t i = 0; i < p.observations.size(); ++i) {
    const RgbdPairObservation& o = p.observations[i];
    PointBlocks& point = n->points[i];
    const Eigen::Vector3d& X = x.points[i];
    const Eigen::Vector3d P = R * X + t;
    if (o.depth2) {
      const Eigen::Vector3d e = o.by_camera2 - k.project(P);
      n->robust_chi2 += addCamera2<3>(e, internal::stereoErrorByPoint(P, k.fx, k.fy, k.bf), P, R,
                                      o.information2, p.huber_delta_stereo, n, &point);
    } else {
      const Eigen::Vector2d e =
          o.by_camera2.head<2>() -
          Eigen::Vector2d(k.fx * P.x() / P.z() + k.cx, k.fy * P.y() / P.z() + k.cy);
      n->robust_chi2 += addCamera2<2>(e, internal::pinholeErrorByPoint(P, k.fx, k.fy), P, R,
                                      o.pixel_information2 * Eigen::Matrix2d::Identity(),
                                      p.huber_delta_pixel, n, &point);
    }
    // Camera 1 is fixed at the identity: the point's own Jacobian alone.
    const Eigen::Vector3d e1 = o.by_camera1 - k.project(X);
    const Eigen::Matrix3d J1 = internal::stereoErrorByPoint(X, k.fx, k.fy, k.bf);
    const double chi2 = e1.dot(o.information1 * e1);
    const Eigen::Matrix3d J1tW =
        J1.transpose() * (huberWeight(chi2, p.huber_delta_stereo) * o.information1);
    point.H.noalias() += J1tW * J1;
    point.b.noalias() -= J1tW * e1;
    n->robust_chi2 += huberCost(chi2, p.huber_delta_stereo);
  }
}

// The damped step with the points eliminated: S = H_pose + lambda I - sum H_pl (H_l + lambda
// I)^-1 H_pl', S dT = b_pose - sum H_pl (H_l + lambda I)^-1 b_l, then each point's step. False
// when S is not positive definite or a step is not finite. *llt keeps S's factor.
struct Step {
  Vector6d pose;
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Matrix3d> damped_inverse;  // (H_l + lambda I)^-1 per point
  Eigen::LLT<Matrix6d> llt;
};

bool solveDamped(const NormalEquations& n, double lambda, Step* step) {
  const size_t count = n.points.size();
  step->points.resize(count);
  step->damped_inverse.resize(count);
  Matrix6d S = n.H_pose;
  S.diagonal().array() += lambda;
  Vector6d rhs = n.b_pose;
  for (size_t i = 0; i < count; ++i) {
    const PointBlocks& point = n.points[i];
    Eigen::Matrix3d A = point.H;
    A.diagonal().array() += lambda;
    step->damped_inverse[i] = A.inverse();
    const Matrix63 HD = point.H_pose_point * step->damped_inverse[i];
    rhs.noalias() -= HD * point.b;
    S.noalias() -= HD * point.H_pose_point.transpose();
  }
  step->llt.compute(S);
  if (step->llt.info() != Eigen::Success) return false;
  step->pose = step->llt.solve(rhs);
  if (!step->pose.allFinite()) return false;
  for (size_t i = 0; i < count; ++i) {
    const PointBlocks& point = n.points[i];
    step->points[i] =
        step->damped_inverse[i] * (point.b - point.H_pose_point.transpose() * step->pose);
    if (!step->points[i].allFinite()) return false;
  }
  return true;
}

// x' (lambda x + b): the decrease of chi2 the damped linear model predicts (g2o's scale).
double predictedReduction(const NormalEquations& n, const Step& step, double lambda) {
  double scale = step.pose.dot(lambda * step.pose + n.b_pose);
  for (size_t i = 0; i < step.points.size(); ++i) {
    scale += step.points[i].dot(lambda * step.points[i] + n.points[i].b);
  }
  return scale;
}

double largestDiagonal(const NormalEquations& n) {
  double largest = n.H_pose.diagonal().cwiseAbs().maxCoeff();
  for (const PointBlocks& point : n.points) {
    largest = std::max(largest, point.H.diagonal().cwiseAbs().maxCoeff());
  }
  return largest;
}

void checkSizes(const RgbdPairProblem& p, const RgbdPairEstimate& x) {
  if (x.points.size() != p.observations.size()) {
    throw Error("rgbd pair: " + std::to_string(x.points.size()) + " points for " +
                std::to_string(p.observations.size()) + " observations");
  }
}

}  // namespace

double rgbdPairRobustChi2(const RgbdPairProblem& p, const RgbdPairEstimate& x) {
  checkSizes(p, x);
  const StereoIntrinsics& k = p.camera;
  const Eigen::Matrix3d R = x.T_21.rotation().toRotationMatrix();
  double chi2 = 0;
  for (size_t i = 0; i < p.observations.size(); ++i) {
    const RgbdPairObservation& o = p.observations[i];
    const Eigen::Vector3d P = R * x.points[i] + x.T_21.translation();
    if (o.depth2) {
      const Eigen::Vector3d e = o.by_camera2 - k.project(P);
      chi2 += huberCost(e.dot(o.information2 * e), p.huber_delta_stereo);
    } else {
      const Eigen::Vector2d e =
          o.by_camera2.head<2>() -
          Eigen::Vector2d(k.fx * P.x() / P.z() + k.cx, k.fy * P.y() / P.z() + k.cy);
      chi2 += huberCost(o.pixel_information2 * e.squaredNorm(), p.huber_delta_pixel);
    }
    const Eigen::Vector3d e1 = o.by_camera1 - k.project(x.points[i]);
    chi2 += huberCost(e1.dot(o.information1 * e1), p.huber_delta_stereo);
  }
  return chi2;
}

int optimizeRgbdPair(const RgbdPairProblem& p, RgbdPairEstimate* x, int iterations,
                     const OptimizerOptions& options) {
  checkSizes(p, *x);
  if (iterations <= 0 || p.observations.empty()) return 0;
  // `current` holds the linearisation at *x; a trial step is linearised as it is evaluated
  // (into `trial`), so an accepted one needs no second pass (the native back end's way).
  NormalEquations current, trial;
  linearize(p, *x, &current);
  const double min_predicted = options.min_relative_predicted_decrease * current.robust_chi2;
  internal::ConvergenceByDecrease convergence(options.min_relative_accepted_decrease *
                                              current.robust_chi2);
  double lambda = options.user_lambda_init > 0 ? options.user_lambda_init
                                               : options.tau * largestDiagonal(current);
  double nu = 2;
  Step step;
  RgbdPairEstimate candidate;
  int done = 0;
  for (int it = 0; it < iterations; ++it) {
    ++done;
    double rho = 0;
    bool converged = false;
    int trials = 0;
    do {
      const bool ok = solveDamped(current, lambda, &step);
      const double predicted = ok ? predictedReduction(current, step, lambda) : 0.0;
      if (ok && trials == 0 && predicted < min_predicted) return done;  // *x untouched
      double new_chi2 = std::numeric_limits<double>::max();
      if (ok) {
        candidate.T_21 = SE3Quat::exp(step.pose) * x->T_21;
        candidate.points = x->points;
        for (size_t i = 0; i < candidate.points.size(); ++i) candidate.points[i] += step.points[i];
        linearize(p, candidate, &trial);
        new_chi2 = trial.robust_chi2;
      }
      const double scale = ok ? predicted + 1e-3 : 1.0;
      rho = (current.robust_chi2 - new_chi2) / scale;
      if (rho > 0 && std::isfinite(new_chi2)) {
        lambda = internal::acceptedStepLambda(lambda, rho);
        nu = 2;
        converged = convergence.convergedAfter(current.robust_chi2 - new_chi2);
        std::swap(current, trial);
        std::swap(*x, candidate);
      } else {
        lambda *= nu;
        nu *= 2;
        if (!std::isfinite(lambda)) break;
      }
      ++trials;
    } while (rho < 0 && trials < options.max_trials_after_failure);
    if (converged) break;
    if (trials == options.max_trials_after_failure || rho == 0 || !std::isfinite(lambda)) break;
  }
  return done;
}

bool rgbdPairCovariance(const RgbdPairProblem& p, const RgbdPairEstimate& x, Matrix6d* covariance) {
  checkSizes(p, x);
  if (p.observations.empty()) return false;
  NormalEquations n;
  linearize(p, x, &n);
  Step step;
  if (!solveDamped(n, 0.0, &step)) return false;
  const Vector6d d = step.llt.matrixLLT().diagonal();
  if (!(d.minCoeff() > 1e-12 * d.maxCoeff())) return false;
  *covariance = step.llt.solve(Matrix6d::Identity());
  return covariance->allFinite();
}

}  // namespace pnpba
