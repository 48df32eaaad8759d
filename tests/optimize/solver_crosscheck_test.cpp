// The two back ends against each other and against an independent dense Levenberg-Marquardt
// with numeric Jacobians, on random graphs with a unique minimum: same final chi2 to 1e-6
// relative.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <memory>

#include "pnpba/optimize/edge_se3_project_xyz.h"
#include "pnpba/optimize/edge_stereo_se3_project_xyz.h"
#include "pnpba/optimize/sparse_optimizer.h"
#include "random_poses.h"

namespace pnpba {
namespace {

constexpr double fx = 517.3, fy = 516.5, cx = 318.6, cy = 255.3, bf = 40.0;

struct GraphSpec {
  int poses = 3;
  int points = 40;
  bool marginalize_points = true;
  bool stereo_in_first_camera = true;  // fixes the scale: the minimum is unique
  double outlier_fraction = 0.0;
  enum Kernel { kNone, kHuber, kCauchy } kernel = kNone;
  bool pose_only = false;  // one pose, points fixed (EdgeSE3ProjectXYZOnlyPose)
};

template <typename EdgeT>
void setIntrinsics(EdgeT* e) {
  e->fx = fx, e->fy = fy, e->cx = cx, e->cy = cy;
}

void addKernel(Edge* e, GraphSpec::Kernel k) {
  if (k == GraphSpec::kHuber) e->setRobustKernel(new RobustKernelHuber(2.0));
  if (k == GraphSpec::kCauchy) e->setRobustKernel(new RobustKernelCauchy(2.0));
}

// Cameras on a short arc looking at a cloud 2-6 m away; noisy pixels, perturbed start.
void buildGraph(SparseOptimizer& opt, const GraphSpec& spec, unsigned seed) {
  test::RandomScene rnd(seed);
  std::vector<SE3Quat> truth;
  for (int k = 0; k < spec.poses; ++k) {
    truth.push_back(k == 0 && !spec.pose_only ? SE3Quat() : rnd.pose(0.15, 0.4));
  }
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < spec.points; ++i) points.push_back(rnd.pointInFront(SE3Quat(), 2.0, 6.0));
  auto noisy_pixel = [&](const Eigen::Vector2d& uv) {
    if (rnd.uniform(0, 1) < spec.outlier_fraction) {
      return Eigen::Vector2d(uv + Eigen::Vector2d(rnd.normal(40), rnd.normal(40)));
    }
    return Eigen::Vector2d(uv + Eigen::Vector2d(rnd.normal(0.7), rnd.normal(0.7)));
  };
  PinholeIntrinsics K{fx, fy, cx, cy};
  // Start perturbations from the scene's own seeded generator: Eigen's Random() draws from the
  // process-wide std::rand, which the tests run before this one would have advanced.
  auto jitter = [&](double half_width, auto* v) {
    for (int k = 0; k < v->size(); ++k) (*v)[k] = rnd.uniform(-half_width, half_width);
  };
  std::vector<VertexSE3Expmap*> poses;
  for (int k = 0; k < spec.poses; ++k) {
    auto* v = new VertexSE3Expmap();
    v->setId(k);
    v->setFixed(k == 0 && !spec.pose_only);
    Vector6d twist;
    jitter(0.03, &twist);
    v->setEstimate(v->fixed() ? truth[k] : SE3Quat::exp(twist) * truth[k]);
    opt.addVertex(v);
    poses.push_back(v);
  }
  if (spec.pose_only) {
    for (int i = 0; i < spec.points; ++i) {
      auto* e = new EdgeSE3ProjectXYZOnlyPose();
      e->setVertex(0, poses[0]);
      e->Xw = points[i];
      setIntrinsics(e);
      e->setMeasurement(noisy_pixel(K.project(truth[0].map(points[i]))));
      addKernel(e, spec.kernel);
      opt.addEdge(e);
    }
    return;
  }
  for (int i = 0; i < spec.points; ++i) {
    auto* p = new VertexPointXYZ();
    p->setId(spec.poses + i);
    p->setMarginalized(spec.marginalize_points);
    Eigen::Vector3d offset;
    jitter(0.05, &offset);
    p->setEstimate(points[i] + offset);
    opt.addVertex(p);
    for (int k = 0; k < spec.poses; ++k) {
      const Eigen::Vector3d P = truth[k].map(points[i]);
      if (k == 0 && spec.stereo_in_first_camera) {
        auto* e = new EdgeStereoSE3ProjectXYZ();
        e->setVertex(0, p);
        e->setVertex(1, poses[k]);
        setIntrinsics(e);
        e->bf = bf;
        const Eigen::Vector2d uv = noisy_pixel(K.project(P));
        e->setMeasurement(Eigen::Vector3d(uv.x(), uv.y(), uv.x() - bf / P.z() + rnd.normal(0.3)));
        addKernel(e, spec.kernel);
        opt.addEdge(e);
      } else {
        auto* e = new EdgeSE3ProjectXYZ();
        e->setVertex(0, p);
        e->setVertex(1, poses[k]);
        setIntrinsics(e);
        e->setMeasurement(noisy_pixel(K.project(P)));
        addKernel(e, spec.kernel);
        opt.addEdge(e);
      }
    }
  }
}

double solveWith(SolverBackend backend, const GraphSpec& spec, unsigned seed) {
  SparseOptimizer opt;
  opt.setSolverBackend(backend);
  buildGraph(opt, spec, seed);
  opt.initializeOptimization();
  opt.optimize(200);
  EXPECT_EQ(opt.summary().backend, backend);
  return opt.activeRobustChi2();
}

// Independent check: dense LM on the stacked whitened residuals, numeric Jacobians through
// the vertices' oplus, no Schur complement, no robust kernel.
double solveDenseNumeric(const GraphSpec& spec, unsigned seed) {
  SparseOptimizer opt;
  buildGraph(opt, spec, seed);
  opt.initializeOptimization();
  std::vector<Vertex*> free;
  int n = 0;
  for (Vertex* v : opt.activeVertices()) {
    if (v->fixed()) continue;
    free.push_back(v);
    n += v->dimension();
  }
  auto residuals = [&]() {
    std::vector<double> r;
    for (Edge* e : opt.activeEdges()) {
      e->computeError();
      const int d = e->dimension();
      const Eigen::Map<const Eigen::MatrixXd> omega(e->informationData(), d, d);
      const Eigen::MatrixXd L = Eigen::LLT<Eigen::MatrixXd>(omega).matrixU();
      const Eigen::VectorXd w = L * Eigen::Map<const Eigen::VectorXd>(e->errorData(), d);
      r.insert(r.end(), w.data(), w.data() + d);
    }
    return Eigen::Map<Eigen::VectorXd>(r.data(), r.size()).eval();
  };
  auto apply = [&](const Eigen::VectorXd& delta) {
    int o = 0;
    for (Vertex* v : free) {
      v->oplus(delta.data() + o);
      o += v->dimension();
    }
  };
  double mu = 1e-3;
  Eigen::VectorXd r = residuals();
  for (int it = 0; it < 200; ++it) {
    Eigen::MatrixXd J(r.size(), n);
    const double h = 1e-7;
    for (int k = 0; k < n; ++k) {
      Eigen::VectorXd d = Eigen::VectorXd::Zero(n);
      d[k] = h;
      for (Vertex* v : free) v->push();
      apply(d);
      const Eigen::VectorXd rp = residuals();
      for (Vertex* v : free) v->pop();
      d[k] = -h;
      for (Vertex* v : free) v->push();
      apply(d);
      const Eigen::VectorXd rm = residuals();
      for (Vertex* v : free) v->pop();
      J.col(k) = (rp - rm) / (2 * h);
    }
    const Eigen::MatrixXd H = J.transpose() * J;
    const Eigen::VectorXd g = J.transpose() * r;
    bool improved = false;
    for (int trial = 0; trial < 20 && !improved; ++trial) {
      Eigen::MatrixXd A = H;
      A.diagonal() += mu * H.diagonal();
      const Eigen::VectorXd delta = A.ldlt().solve(-g);
      for (Vertex* v : free) v->push();
      apply(delta);
      const Eigen::VectorXd r_new = residuals();
      if (r_new.squaredNorm() < r.squaredNorm()) {
        for (Vertex* v : free) v->discardTop();
        improved = r.squaredNorm() - r_new.squaredNorm() > 1e-15 * r.squaredNorm();
        r = r_new;
        mu = std::max(mu / 10, 1e-12);
        if (!improved) return r.squaredNorm();
      } else {
        for (Vertex* v : free) v->pop();
        mu *= 10;
      }
    }
    if (!improved) break;
  }
  return residuals().squaredNorm();
}

void expectSameMinimum(const GraphSpec& spec, unsigned seed, bool with_dense) {
  const double native = solveWith(SolverBackend::kNative, spec, seed);
  const double ceres = solveWith(SolverBackend::kCeres, spec, seed);
  EXPECT_NEAR(native, ceres, 1e-6 * ceres) << "seed " << seed;
  if (with_dense) {
    const double dense = solveDenseNumeric(spec, seed);
    EXPECT_NEAR(native, dense, 1e-6 * dense) << "seed " << seed;
  }
}

TEST(SolverCrossCheck, SchurBundleAdjustmentAgreesWithCeresAndDenseLm) {
  for (unsigned seed : {1u, 2u, 3u}) expectSameMinimum(GraphSpec{}, seed, true);
}

TEST(SolverCrossCheck, UnmarginalizedPointsAgree) {
  GraphSpec spec;
  spec.marginalize_points = false;
  spec.points = 20;
  expectSameMinimum(spec, 4, true);
}

// With 10 % outliers of 40 px under Huber the cost has several local minima, and the two back
// ends' different damping schedules may reach different ones from the same start (measured: 4
// of 12 seeds, the native back end lower each time). What must hold is that they minimise the
// same function: where one stops, the other finds nothing lower.
TEST(SolverCrossCheck, HuberWithOutliersEachMinimumIsAMinimumForTheOther) {
  GraphSpec spec;
  spec.kernel = GraphSpec::kHuber;
  spec.outlier_fraction = 0.1;
  for (unsigned seed = 1; seed <= 12; ++seed) {
    for (SolverBackend first : {SolverBackend::kNative, SolverBackend::kCeres}) {
      const SolverBackend second =
          first == SolverBackend::kNative ? SolverBackend::kCeres : SolverBackend::kNative;
      SparseOptimizer opt;
      opt.setSolverBackend(first);
      buildGraph(opt, spec, seed);
      opt.initializeOptimization();
      opt.computeActiveErrors();
      const double start = opt.activeRobustChi2();
      opt.optimize(200);
      const double reached = opt.activeRobustChi2();
      EXPECT_LT(reached, 0.9 * start) << "seed " << seed;
      opt.setSolverBackend(second);
      opt.initializeOptimization();
      opt.optimize(200);
      EXPECT_GT(opt.activeRobustChi2(), reached * (1 - 1e-6))
          << "seed " << seed << ": " << toString(second) << " went below " << toString(first);
    }
  }
}

TEST(SolverCrossCheck, PoseOnlyWithCauchyAgrees) {
  GraphSpec spec;
  spec.pose_only = true;
  spec.poses = 1;
  spec.points = 60;
  spec.kernel = GraphSpec::kCauchy;
  spec.outlier_fraction = 0.2;
  expectSameMinimum(spec, 7, false);
}

TEST(SolverCrossCheck, PoseOnlyLeastSquaresAgreesWithDenseLm) {
  GraphSpec spec;
  spec.pose_only = true;
  spec.poses = 1;
  spec.points = 60;
  expectSameMinimum(spec, 8, true);
}

}  // namespace
}  // namespace pnpba
