#include "pnpba/optimize/rgbd_pair.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "huber.h"
#include "lm_damping.h"
#include "pnpba/core/cpu_features.h"
#include "pnpba/core/error.h"
#include "two_view_camera.h"
#include "two_view_loops.h"

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

using internal::huberCost;

// The loops of the instruction set this CPU runs (two_view_loops.h).
struct Loops {
  decltype(&two_view::evaluateStereoPairs) evaluate;
  decltype(&two_view::assemble) assemble;
  decltype(&two_view::maxDiagonal) max_diagonal;
  decltype(&two_view::eliminate) eliminate;
  decltype(&two_view::backSubstitute) back_substitute;
};
const Loops& loops() {
  static const Loops chosen =
      cpuHasAvx2Fma() ? Loops{two_view::avx2::evaluateStereoPairs, two_view::avx2::assemble,
                              two_view::avx2::maxDiagonal, two_view::avx2::eliminate,
                              two_view::avx2::backSubstitute}
                      : Loops{two_view::evaluateStereoPairs, two_view::assemble,
                              two_view::maxDiagonal, two_view::eliminate, two_view::backSubstitute};
  return chosen;
}

// `count` arrays of one value per point (lane-major), carved from one buffer.
class LaneArrays {
 public:
  void resize(size_t n, size_t count) {
    n_ = n;
    data_.assign(n * count, 0.0);
  }
  double* operator[](size_t k) { return data_.data() + k * n_; }

 private:
  size_t n_ = 0;
  std::vector<double> data_;
};

// The problem's constants per point, one lane each (two_view::StereoPairArrays): camera 1's and
// camera 2's measurements and informations (camera 2 without depth: (u, v, 0) and the pixel
// information on the first two rows), camera 2's Huber width.
struct Constants {
  LaneArrays lanes;  // z1 (3), info1 (6), z2 (3), info2 (6), delta2 (1)
  explicit Constants(const RgbdPairProblem& p) {
    const size_t n = p.observations.size();
    lanes.resize(n, 19);
    for (size_t i = 0; i < n; ++i) {
      const RgbdPairObservation& o = p.observations[i];
      const Eigen::Matrix3d info2 =
          o.depth2
              ? o.information2
              : Eigen::Matrix3d(
                    Eigen::Vector3d(o.pixel_information2, o.pixel_information2, 0).asDiagonal());
      const double values[19] = {o.by_camera1.x(),
                                 o.by_camera1.y(),
                                 o.by_camera1.z(),
                                 o.information1(0, 0),
                                 o.information1(0, 1),
                                 o.information1(0, 2),
                                 o.information1(1, 1),
                                 o.information1(1, 2),
                                 o.information1(2, 2),
                                 o.by_camera2.x(),
                                 o.by_camera2.y(),
                                 o.depth2 ? o.by_camera2.z() : 0,
                                 info2(0, 0),
                                 info2(0, 1),
                                 info2(0, 2),
                                 info2(1, 1),
                                 info2(1, 2),
                                 info2(2, 2),
                                 o.depth2 ? p.huber_delta_stereo : p.huber_delta_pixel};
      for (size_t k = 0; k < 19; ++k) lanes[k][i] = values[k];
    }
  }
};

// The normal equations of one linearisation, points not yet eliminated (two_view_loops.h's
// PointArrays): per point its camera-2 terms P, M, g and camera 1's F, f; the point's
// information and gradient in camera 2's frame (H2, b2) and in the world frame (bl); the pose's
// gradient bp; the robust chi2.
struct NormalEquations {
  two_view::CameraPose camera{};
  LaneArrays lanes;  // x y z (3), P (3), M (6), g (3), F (6), f (3), cost (1), H2 (6), b2 (3)
  std::vector<double> bl;
  double bp[6] = {};
  double robust_chi2 = 0;
  size_t n = 0;

  two_view::PointArrays points() {
    two_view::PointArrays a;
    a.n = n;
    for (int k = 0; k < 3; ++k) {
      a.p[k] = lanes[3 + k], a.g[k] = lanes[12 + k], a.f[k] = lanes[21 + k];
      a.b2[k] = lanes[31 + k];
    }
    for (int k = 0; k < 6; ++k) {
      a.m[k] = lanes[6 + k], a.F[k] = lanes[15 + k], a.h2[k] = lanes[25 + k];
    }
    return a;
  }
};

// Linearises every error at the estimate into *n (the graph's maths: camera 2's error then
// camera 1's per point; sums in the vector width's order).
void linearize(const RgbdPairProblem& p, Constants& c, const RgbdPairEstimate& x,
               NormalEquations* n) {
  const size_t count = p.observations.size();
  if (n->n != count) {
    n->n = count;
    n->lanes.resize(count, 34);
    n->bl.assign(3 * count, 0.0);
  }
  n->camera = cameraPoseOf(x.T_21);
  for (size_t i = 0; i < count; ++i) {
    for (int k = 0; k < 3; ++k) n->lanes[k][i] = x.points[i][k];
  }
  two_view::StereoPairArrays a;
  a.n = count;
  const StereoIntrinsics& k = p.camera;
  a.fx = k.fx, a.fy = k.fy, a.cx = k.cx, a.cy = k.cy, a.bf = k.bf;
  a.delta1 = p.huber_delta_stereo;
  a.x = n->lanes[0], a.y = n->lanes[1], a.z = n->lanes[2];
  for (int j = 0; j < 3; ++j) a.z1[j] = c.lanes[j], a.z2[j] = c.lanes[9 + j];
  for (int j = 0; j < 6; ++j) a.info1[j] = c.lanes[3 + j], a.info2[j] = c.lanes[12 + j];
  a.delta2 = c.lanes[18];
  for (int j = 0; j < 3; ++j) {
    a.p[j] = n->lanes[3 + j], a.g[j] = n->lanes[12 + j], a.f[j] = n->lanes[21 + j];
  }
  for (int j = 0; j < 6; ++j) a.m[j] = n->lanes[6 + j], a.F[j] = n->lanes[15 + j];
  a.cost = n->lanes[24];
  n->robust_chi2 = loops().evaluate(n->camera, a);
  loops().assemble(n->camera, n->points(), n->bl.data(), n->bp);
}

// The damped step with the points eliminated (two_view_loops.h's eliminate, in camera 2's
// frame), then each point's step (world frame). False when S is not positive definite or a step
// is not finite. *llt keeps S's factor.
struct Step {
  Vector6d pose;
  std::vector<double> points;  // three per point
  LaneArrays scratch;          // (H2 + lambda I)^-1 (6) and the elimination's terms
  size_t n = 0;
  Eigen::LLT<Matrix6d> llt;
};

bool solveDamped(NormalEquations& n, double lambda, Step* step) {
  if (step->n != n.n) {
    step->n = n.n;
    step->points.assign(3 * n.n, 0.0);
    step->scratch.resize(n.n, 6 + two_view::kEliminationTerms);
  }
  two_view::PointArrays a = n.points();
  for (int k = 0; k < 6; ++k) a.ninv[k] = step->scratch[k];
  a.terms = step->scratch[6];
  Matrix6d S = Matrix6d::Zero();
  Vector6d rhs;
  loops().eliminate(a, lambda, S.data(), rhs.data());
  step->llt.compute(S);
  if (step->llt.info() != Eigen::Success) return false;
  step->pose = step->llt.solve(rhs);
  if (!step->pose.allFinite()) return false;
  loops().back_substitute(n.camera, a, step->pose.data(), step->points.data());
  for (double v : step->points) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

// x' (lambda x + b): the decrease of chi2 the damped linear model predicts (g2o's scale).
double predictedReduction(const NormalEquations& n, const Step& step, double lambda) {
  double scale = 0;
  for (int k = 0; k < 6; ++k) scale += step.pose[k] * (lambda * step.pose[k] + n.bp[k]);
  for (size_t i = 0; i < step.points.size(); ++i) {
    scale += step.points[i] * (lambda * step.points[i] + n.bl[i]);
  }
  return scale;
}

double largestDiagonal(NormalEquations& n) { return loops().max_diagonal(n.camera, n.points()); }

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
  Constants constants(p);
  NormalEquations current, trial;
  linearize(p, constants, *x, &current);
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
        for (size_t i = 0; i < candidate.points.size(); ++i) {
          candidate.points[i] += Eigen::Map<const Eigen::Vector3d>(step.points.data() + 3 * i);
        }
        linearize(p, constants, candidate, &trial);
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
  Constants constants(p);
  NormalEquations n;
  linearize(p, constants, x, &n);
  Step step;
  if (!solveDamped(n, 0.0, &step)) return false;
  const Vector6d d = step.llt.matrixLLT().diagonal();
  if (!(d.minCoeff() > 1e-12 * d.maxCoeff())) return false;
  *covariance = step.llt.solve(Matrix6d::Identity());
  return covariance->allFinite();
}

}  // namespace pnpba
