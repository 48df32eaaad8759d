// The dedicated two-view RGB-D solver against the graph engine it replaces: a SparseOptimizer
// with camera 2's VertexSE3Expmap, a fixed camera 1 at the identity, a marginalised
// VertexPointXYZ per point, camera 1's EdgeStereoSE3ProjectXYZ and camera 2's stereo or pinhole
// edge, on random problems with noise, outliers, per-observation information and Huber or not.
// Same pose, points, chi2, iteration count and covariance, to round-off; and, on exact data, the
// truth.
#include "pnpba/optimize/rgbd_pair.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>

#include "pnpba/core/error.h"
#include "pnpba/optimize/edge_se3_project_xyz.h"
#include "pnpba/optimize/vertex_point_xyz.h"
#include "pnpba/optimize/vertex_se3_expmap.h"

namespace pnpba {
namespace {

struct Case {
  RgbdPairProblem problem;
  RgbdPairEstimate start;
  SE3Quat truth;
  std::vector<Eigen::Vector3d> true_points;
};

Eigen::Matrix3d randomInformation(std::mt19937& rng) {
  // A pixel's noise on u and v, and a disparity's: u and u_r share u's (pose_graph.cpp's form).
  std::uniform_real_distribution<double> sigma(0.5, 2.0), disparity(0.5, 3.0);
  const double s2 = std::pow(sigma(rng), 2), d2 = std::pow(disparity(rng), 2);
  Eigen::Matrix3d covariance;
  covariance << s2, 0, s2, 0, s2, 0, s2, 0, s2 + d2;
  return covariance.inverse();
}

Case randomCase(unsigned seed, bool huber, double outliers, double noise) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1, 1), depth(1, 6), chance(0, 1);
  std::normal_distribution<double> gauss(0, 1);
  Vector6d xi;
  for (int k = 0; k < 6; ++k) xi(k) = (k < 3 ? 0.3 : 0.8) * unit(rng);
  Case c;
  c.truth = SE3Quat::exp(xi);
  RgbdPairProblem& p = c.problem;
  p.camera = {520.9, 521.0, 325.1, 249.7, 52.09};
  if (huber) p.huber_delta_stereo = std::sqrt(7.815), p.huber_delta_pixel = std::sqrt(5.991);
  const int n = 30 + static_cast<int>(seed % 50);
  Vector6d off;
  for (int k = 0; k < 6; ++k) off(k) = 0.03 * unit(rng);
  c.start.T_21 = SE3Quat::exp(off) * c.truth;
  while (static_cast<int>(p.observations.size()) < n) {
    const Eigen::Vector3d X(2 * unit(rng), 1.5 * unit(rng), depth(rng));
    const Eigen::Vector3d P = c.truth.map(X);
    if (P.z() < 0.3) continue;
    RgbdPairObservation o;
    const Eigen::Vector3d jitter1(gauss(rng), gauss(rng), 2 * gauss(rng));
    o.by_camera1 = p.camera.project(X) + noise * jitter1;
    o.information1 = randomInformation(rng);
    o.depth2 = chance(rng) < 0.7;
    const Eigen::Vector3d jitter2(gauss(rng), gauss(rng), 2 * gauss(rng));
    o.by_camera2 = p.camera.project(P) + noise * jitter2;
    // Pixels Huber weighs down: the final graph's pairs passed the outlier rounds, and a point
    // whose camera-2 pixel is tens of pixels off runs off along camera 1's ray.
    if (chance(rng) < outliers) o.by_camera2.head<2>() += 8 * Eigen::Vector2d(unit(rng), unit(rng));
    if (o.depth2) {
      o.information2 = randomInformation(rng);
    } else {
      o.by_camera2.z() = 0;
      o.pixel_information2 = 1.0 / std::pow(1.2, static_cast<int>(8 * chance(rng)));
    }
    p.observations.push_back(o);
    c.true_points.push_back(X);
    c.start.points.push_back(X + 0.02 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)));
  }
  return c;
}

// The same problem as a graph.
struct Graph {
  SparseOptimizer optimizer;
  VertexSE3Expmap* pose = nullptr;
  std::vector<VertexPointXYZ*> points;
  explicit Graph(const Case& c) {
    const RgbdPairProblem& p = c.problem;
    const StereoIntrinsics& k = p.camera;
    pose = new VertexSE3Expmap();
    pose->setId(0);
    pose->setEstimate(c.start.T_21);
    optimizer.addVertex(pose);
    auto* camera1 = new VertexSE3Expmap();
    camera1->setId(1);
    camera1->setFixed(true);
    optimizer.addVertex(camera1);
    int id = 0;
    auto kernel = [](double delta) -> RobustKernel* {
      return delta > 0 ? new RobustKernelHuber(delta) : nullptr;
    };
    // A pixel-and-depth observation of `point` by `camera`.
    auto addStereo = [&](VertexPointXYZ* point, VertexSE3Expmap* camera, const Eigen::Vector3d& z,
                         const Eigen::Matrix3d& information) {
      auto* e = new EdgeStereoSE3ProjectXYZ();
      e->fx = k.fx, e->fy = k.fy, e->cx = k.cx, e->cy = k.cy, e->bf = k.bf;
      e->setMeasurement(z);
      e->setInformation(information);
      e->setRobustKernel(kernel(p.huber_delta_stereo));
      e->setId(id++), e->setVertex(0, point), e->setVertex(1, camera);
      optimizer.addEdge(e);
    };
    for (size_t i = 0; i < p.observations.size(); ++i) {
      const RgbdPairObservation& o = p.observations[i];
      auto* point = new VertexPointXYZ();
      point->setId(2 + static_cast<int>(i));
      point->setEstimate(c.start.points[i]);
      point->setMarginalized(true);
      optimizer.addVertex(point);
      points.push_back(point);
      if (o.depth2) {
        addStereo(point, pose, o.by_camera2, o.information2);
      } else {
        auto* e = new EdgeSE3ProjectXYZ();
        e->fx = k.fx, e->fy = k.fy, e->cx = k.cx, e->cy = k.cy;
        e->setMeasurement(o.by_camera2.head<2>());
        e->setInformation(o.pixel_information2 * Eigen::Matrix2d::Identity());
        e->setRobustKernel(kernel(p.huber_delta_pixel));
        e->setId(id++), e->setVertex(0, point), e->setVertex(1, pose);
        optimizer.addEdge(e);
      }
      addStereo(point, camera1, o.by_camera1, o.information1);
    }
    optimizer.setSolverBackend(SolverBackend::kNative);
    optimizer.initializeOptimization();
  }
};

TEST(RgbdPair, MatchesTheGraphEngineOnRandomProblems) {
  int compared = 0;
  for (unsigned seed = 1; seed <= 60; ++seed) {
    for (bool huber : {false, true}) {
      const Case c = randomCase(seed, huber, huber ? 0.2 : 0.0, 1.0);
      Graph g(c);
      g.optimizer.computeActiveErrors();
      const double graph_initial = g.optimizer.activeRobustChi2();
      const int graph_iterations = g.optimizer.optimize(50);
      const double graph_final = g.optimizer.activeRobustChi2();
      Eigen::MatrixXd graph_covariance;
      const bool graph_ok = g.optimizer.computeMarginalCovariance(0, &graph_covariance);

      RgbdPairEstimate x = c.start;
      EXPECT_NEAR(rgbdPairRobustChi2(c.problem, x), graph_initial, 1e-10 * graph_initial);
      const int iterations = optimizeRgbdPair(c.problem, &x, 50);
      EXPECT_EQ(iterations, graph_iterations) << seed << " " << huber;
      EXPECT_NEAR(rgbdPairRobustChi2(c.problem, x), graph_final, 1e-9 * (1 + graph_final));
      EXPECT_LT((x.T_21 * g.pose->estimate().inverse()).log().norm(), 1e-9) << seed;
      for (size_t i = 0; i < x.points.size(); ++i) {
        ASSERT_LT((x.points[i] - g.points[i]->estimate()).norm(), 1e-9) << seed << " " << i;
      }
      Matrix6d covariance;
      ASSERT_EQ(rgbdPairCovariance(c.problem, x, &covariance), graph_ok);
      if (graph_ok) {
        EXPECT_LT((covariance - graph_covariance).norm(), 1e-8 * graph_covariance.norm()) << seed;
      }
      ++compared;
    }
  }
  EXPECT_EQ(compared, 120);
}

TEST(RgbdPair, FindsTheTruthFromExactObservations) {
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const Case c = randomCase(seed, true, 0.0, 0.0);
    RgbdPairEstimate x = c.start;
    OptimizerOptions to_the_floor;  // no early stop: LM runs until no step improves
    to_the_floor.min_relative_predicted_decrease = to_the_floor.min_relative_accepted_decrease = 0;
    optimizeRgbdPair(c.problem, &x, 100, to_the_floor);
    EXPECT_LT((x.T_21 * c.truth.inverse()).log().norm(), 1e-9) << seed;
    for (size_t i = 0; i < x.points.size(); ++i) {
      EXPECT_LT((x.points[i] - c.true_points[i]).norm(), 1e-9) << seed << " " << i;
    }
    EXPECT_LT(rgbdPairRobustChi2(c.problem, x), 1e-16);
    // Every pose direction is pinned by the depths: a positive-definite covariance.
    Matrix6d covariance;
    ASSERT_TRUE(rgbdPairCovariance(c.problem, x, &covariance));
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<Matrix6d>(covariance).eigenvalues().minCoeff(), 0);
  }
}

TEST(RgbdPair, DegreesOfFreedomCountTheErrorsLessTheUnknowns) {
  const Case c = randomCase(3, true, 0.0, 1.0);
  int dims = 0;
  for (const RgbdPairObservation& o : c.problem.observations) dims += 3 + (o.depth2 ? 3 : 2);
  EXPECT_EQ(c.problem.degreesOfFreedom(),
            dims - 6 - 3 * static_cast<int>(c.problem.observations.size()));
}

TEST(RgbdPair, NoObservationIsNothingToDoAndAMismatchIsAnError) {
  RgbdPairProblem empty;
  RgbdPairEstimate x;
  EXPECT_EQ(optimizeRgbdPair(empty, &x, 10), 0);
  EXPECT_EQ(empty.degreesOfFreedom(), 0);
  Matrix6d covariance;
  EXPECT_FALSE(rgbdPairCovariance(empty, x, &covariance));
  const Case c = randomCase(4, false, 0.0, 1.0);
  RgbdPairEstimate short_of_points = c.start;
  short_of_points.points.pop_back();
  EXPECT_THROW(optimizeRgbdPair(c.problem, &short_of_points, 10), Error);
  EXPECT_THROW(rgbdPairRobustChi2(c.problem, short_of_points), Error);
}

}  // namespace
}  // namespace pnpba
