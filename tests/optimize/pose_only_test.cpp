// The dedicated motion-only solver against the graph engine it replaces: a SparseOptimizer with
// one VertexSE3Expmap and an EdgeSE3ProjectXYZOnlyPose per observation, on random problems
// with noise, outliers, per-observation information, Huber or not, and inactive observations.
// Same pose, chi2, iteration count and covariance, to round-off.
#include "pnpba/optimize/pose_only.h"

#include <gtest/gtest.h>

#include <random>

#include "pnpba/optimize/vertex_se3_expmap.h"

namespace pnpba {
namespace {

struct Case {
  PoseOnlyProblem problem;
  SE3Quat start;
};

Case randomCase(unsigned seed, bool huber, double outliers) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1, 1), depth(1, 6), chance(0, 1);
  std::normal_distribution<double> pixel(0, 1);
  Vector6d xi;
  for (int k = 0; k < 6; ++k) xi(k) = (k < 3 ? 0.3 : 0.8) * unit(rng);
  const SE3Quat truth = SE3Quat::exp(xi);
  Case c;
  c.problem.camera = {520.9, 521.0, 325.1, 249.7};
  c.problem.huber_delta = huber ? std::sqrt(5.991) : 0.0;
  const int n = 40 + static_cast<int>(seed % 60);
  while (static_cast<int>(c.problem.size()) < n) {
    const Eigen::Vector3d X(2 * unit(rng), 1.5 * unit(rng), depth(rng));
    const Eigen::Vector3d P = truth.map(X);
    if (P.z() < 0.3) continue;
    Eigen::Vector2d uv = c.problem.camera.project(P) + Eigen::Vector2d(pixel(rng), pixel(rng));
    if (chance(rng) < outliers) uv += Eigen::Vector2d(80 * unit(rng), 80 * unit(rng));
    const double sigma = std::pow(1.2, static_cast<int>(8 * chance(rng)));  // ORB levels
    c.problem.add(X, uv, 1.0 / (sigma * sigma));
    if (chance(rng) < 0.1) c.problem.active.back() = 0;
  }
  Vector6d off;
  for (int k = 0; k < 6; ++k) off(k) = 0.05 * unit(rng);
  c.start = SE3Quat::exp(off) * truth;
  return c;
}

// The same problem as a graph.
struct Graph {
  SparseOptimizer optimizer;
  VertexSE3Expmap* pose = nullptr;
  explicit Graph(const Case& c) {
    pose = new VertexSE3Expmap();
    pose->setId(0);
    pose->setEstimate(c.start);
    optimizer.addVertex(pose);
    const PoseOnlyProblem& p = c.problem;
    for (size_t i = 0; i < p.size(); ++i) {
      auto* e = new EdgeSE3ProjectXYZOnlyPose();
      e->setId(static_cast<int>(i));
      e->setVertex(0, pose);
      e->setMeasurement(p.pixels[i]);
      e->setInformation(p.information[i] * Eigen::Matrix2d::Identity());
      e->Xw = p.points[i];
      e->fx = p.camera.fx, e->fy = p.camera.fy, e->cx = p.camera.cx, e->cy = p.camera.cy;
      if (p.huber_delta > 0) e->setRobustKernel(new RobustKernelHuber(p.huber_delta));
      e->setLevel(p.active[i] ? 0 : 1);
      optimizer.addEdge(e);
    }
    optimizer.setSolverBackend(SolverBackend::kNative);
    optimizer.initializeOptimization(0);
  }
};

TEST(PoseOnly, MatchesTheGraphEngineOnRandomProblems) {
  int checked = 0;
  for (unsigned seed = 1; seed <= 60; ++seed) {
    for (bool huber : {false, true}) {
      const Case c = randomCase(seed, huber, huber ? 0.2 : 0.0);
      for (int iterations : {1, 3, 10, 100}) {
        Graph g(c);
        const int graph_iterations = g.optimizer.optimize(iterations);
        SE3Quat T = c.start;
        const int own_iterations = optimizePoseOnly(c.problem, &T, iterations);
        EXPECT_EQ(own_iterations, graph_iterations) << seed << " " << huber << " " << iterations;
        const Vector6d d = (T * g.pose->estimate().inverse()).log();
        EXPECT_LT(d.norm(), 1e-9) << seed << " " << huber << " " << iterations;
        g.optimizer.computeActiveErrors();
        EXPECT_NEAR(poseOnlyRobustChi2(c.problem, T), g.optimizer.activeRobustChi2(),
                    1e-9 * (1 + g.optimizer.activeRobustChi2()));
        Eigen::MatrixXd graph_cov;
        Matrix6d own_cov;
        const bool graph_ok = g.optimizer.computeMarginalCovariance(0, &graph_cov);
        ASSERT_EQ(poseOnlyCovariance(c.problem, T, &own_cov), graph_ok);
        if (graph_ok) {
          EXPECT_LT((own_cov - graph_cov).norm(), 1e-9 * graph_cov.norm());
        }
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 60 * 2 * 4);
}

TEST(PoseOnly, PerObservationQueriesMatchTheEdges) {
  const Case c = randomCase(5, true, 0.3);
  Graph g(c);
  g.optimizer.initializeOptimization(-1);  // every level
  for (size_t i = 0; i < c.problem.size(); ++i) {
    auto* e = static_cast<EdgeSE3ProjectXYZOnlyPose*>(g.optimizer.edges()[i]);
    e->computeError();
    EXPECT_DOUBLE_EQ(poseOnlyChi2(c.problem, i, c.start), e->chi2());
    EXPECT_EQ(poseOnlyDepthPositive(c.problem, i, c.start), e->isDepthPositive());
  }
}

TEST(PoseOnly, NothingActiveIsNothingToDo) {
  Case c = randomCase(3, false, 0.0);
  std::fill(c.problem.active.begin(), c.problem.active.end(), 0);
  SE3Quat T = c.start;
  EXPECT_EQ(optimizePoseOnly(c.problem, &T, 10), 0);
  Matrix6d cov;
  EXPECT_FALSE(poseOnlyCovariance(c.problem, T, &cov));
}

}  // namespace
}  // namespace pnpba
