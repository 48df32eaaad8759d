// BAL: the camera edge's analytic Jacobians against central differences, the dubrovnik cut
// against an independent Ceres autodiff solve, a synthetic problem with exact ground truth,
// and the reader on every kind of malformed file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "pnpba/bal/bal_problem.h"
#include "pnpba/core/error.h"
#include "random_poses.h"
#include "scratch_dir.h"
#include "shared_data.h"
#include "snavely_autodiff.h"

namespace pnpba {
namespace {

namespace fs = std::filesystem;

// Central differences of the edge error through the vertex's own oplus.
template <typename EdgeT>
Eigen::MatrixXd numeric(EdgeT& e, Vertex& v) {
  const double h = 1e-6;
  Eigen::MatrixXd J(2, v.dimension());
  for (int k = 0; k < v.dimension(); ++k) {
    Eigen::VectorXd d = Eigen::VectorXd::Zero(v.dimension());
    Eigen::Vector2d plus, minus;
    for (double sign : {1.0, -1.0}) {
      d[k] = sign * h;
      v.push();
      v.oplus(d.data());
      e.computeError();
      (sign > 0 ? plus : minus) = e.error();
      v.pop();
    }
    J.col(k) = (plus - minus) / (2 * h);
  }
  return J;
}

TEST(BalEdge, AnalyticJacobiansMatchCentralDifferences) {
  test::RandomScene rnd(31);
  double worst_camera = 0, worst_point = 0;
  for (int i = 0; i < 50; ++i) {
    BalCamera c;
    c.pose = rnd.pose(M_PI / 2, 2.0);
    c.f = rnd.uniform(300, 900);
    c.k1 = rnd.uniform(-0.3, 0.3);
    c.k2 = rnd.uniform(-0.1, 0.1);
    // BAL cameras look down -z: put the point at negative camera z.
    const Eigen::Vector3d P(rnd.uniform(-1, 1), rnd.uniform(-1, 1), -rnd.uniform(0.3, 20));
    VertexBalCamera camera;
    camera.setEstimate(c);
    VertexPointXYZ point;
    point.setEstimate(c.pose.inverse().map(P));
    EdgeBalProjection e;
    e.setVertex(0, &point);
    e.setVertex(1, &camera);
    e.setMeasurement(c.project(point.estimate()) + Eigen::Vector2d(2, -3));
    e.linearizeOplus();
    const Eigen::MatrixXd Nc = numeric(e, camera), Np = numeric(e, point);
    worst_camera = std::max(worst_camera, (e.jacobianOplusXj() - Nc).norm() / Nc.norm());
    worst_point = std::max(worst_point, (e.jacobianOplusXi() - Np).norm() / Np.norm());
  }
  EXPECT_LE(worst_camera, 1e-6);
  EXPECT_LE(worst_point, 1e-6);
}

TEST(BalProblem, ParametersRoundTripThroughTheCamera) {
  const double p[9] = {0.1, -0.2, 0.3, 1, 2, 3, 500, -0.1, 0.01};
  double back[9];
  BalCamera::fromParameters(p).toParameters(back);
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(back[i], p[i], 1e-12);
}

// dubrovnik-3-7 has 38 residuals for 48 unknowns: its cost goes to zero, so it is checked for
// convergence with a strictly decreasing cost ...
TEST(BalSolve, DubrovnikConvergesWithStrictlyDecreasingCost) {
  PNPBA_REQUIRE_SHARED_DATA();
  BalProblem p = readBal(test::sharedData("bal/dubrovnik-3-7-pre.txt"));
  SparseOptimizer optimizer;
  optimizer.setSolverBackend(SolverBackend::kCeres);
  buildBalGraph(optimizer, p);
  optimizer.initializeOptimization();
  std::vector<double> costs;
  optimizer.setIterationCallback([&](const IterationStats& s) {
    if (s.levenberg_trials > 0) costs.push_back(0.5 * s.chi2);  // accepted steps
  });
  optimizer.computeActiveErrors();
  const double initial = 0.5 * optimizer.chi2();
  optimizer.optimize(50);
  const double final_cost = 0.5 * optimizer.chi2();
  readBalGraph(optimizer, p);
  EXPECT_NEAR(p.cost(), final_cost, 1e-9 * initial);  // graph and file model agree
  ASSERT_FALSE(costs.empty());
  EXPECT_LT(costs.front(), initial);
  for (size_t i = 1; i < costs.size(); ++i) EXPECT_LT(costs[i], costs[i - 1]) << "step " << i;
  EXPECT_LT(final_cost, 1e-4 * initial);
}

// ... and, with cameras 0 and 1 held fixed (30 unknowns, 38 residuals: a unique minimum),
// against an independent solve: Ceres with automatic derivatives of the Snavely model on the
// raw angle-axis parameters.
TEST(BalSolve, DubrovnikMatchesIndependentCeresAutodiff) {
  PNPBA_REQUIRE_SHARED_DATA();
  const BalProblem original = readBal(test::sharedData("bal/dubrovnik-3-7-pre.txt"));
  BalProblem ours = original, theirs = original;
  SparseOptimizer optimizer;
  optimizer.setSolverBackend(SolverBackend::kCeres);
  optimizer.options().function_tolerance = 1e-15;
  buildBalGraph(optimizer, ours);
  optimizer.vertex(0)->setFixed(true);
  optimizer.vertex(1)->setFixed(true);
  optimizer.initializeOptimization();
  optimizer.computeActiveErrors();
  const double initial = 0.5 * optimizer.chi2();
  optimizer.optimize(200);
  const double final_cost = 0.5 * optimizer.chi2();

  const test::AutodiffSolve reference =
      test::solveWithCeresAutodiff(theirs, 200, 1, ceres::DENSE_SCHUR, 1e-15, {0, 1});
  EXPECT_NEAR(reference.initial_cost, initial, 1e-9 * initial);
  EXPECT_GT(final_cost, 1e-6 * initial);  // a real minimum, not zero
  EXPECT_NEAR(final_cost, reference.final_cost, 1e-6 * reference.final_cost);
}

TEST(BalSolve, SyntheticProblemIsRecoveredExactly) {
  // 6 cameras on an arc looking at 300 points, noise-free observations, then perturbed.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(-1, 1);
  BalProblem p;
  p.num_cameras = 6;
  p.num_points = 300;
  for (int q = 0; q < p.num_points; ++q) {
    p.points.insert(p.points.end(), {2 * unit(rng), 2 * unit(rng), 2 * unit(rng)});
  }
  for (int c = 0; c < p.num_cameras; ++c) {
    const double angle = 0.15 * (c - 2.5);
    BalCamera cam;
    // Camera at distance 8 looking at the origin along its -z axis.
    const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
    cam.pose = SE3Quat(R, Eigen::Vector3d(0, 0, -8));
    cam.f = 500 + 20 * c;
    cam.k1 = 0.01 * c;
    cam.k2 = -0.002 * c;
    double params[9];
    cam.toParameters(params);
    p.cameras.insert(p.cameras.end(), params, params + 9);
    for (int q = 0; q < p.num_points; ++q) {
      const Eigen::Vector2d uv = cam.project(Eigen::Map<const Eigen::Vector3d>(&p.points[3 * q]));
      p.observations.push_back({c, q, uv.x(), uv.y()});
    }
  }
  ASSERT_LT(p.rmsPixels(), 1e-9);
  BalPerturbation noise;
  noise.rotation_sigma = 0.01;
  noise.translation_sigma = 0.05;
  noise.point_sigma = 0.05;
  perturbBal(p, noise);
  const double rms_initial = p.rmsPixels();
  ASSERT_GT(rms_initial, 1.0);
  SparseOptimizer optimizer;
  optimizer.setSolverBackend(SolverBackend::kCeres);
  buildBalGraph(optimizer, p);
  optimizer.initializeOptimization();
  optimizer.optimize(100);
  readBalGraph(optimizer, p);
  EXPECT_LT(p.rmsPixels(), 1e-6 * rms_initial);
}

TEST(BalProblem, NormalizationKeepsTheCost) {
  PNPBA_REQUIRE_SHARED_DATA();
  BalProblem p = readBal(test::sharedData("bal/dubrovnik-3-7-pre.txt"));
  const double before = p.cost();
  normalizeBal(p);
  EXPECT_NEAR(p.cost(), before, 1e-8 * before);
}

std::string errorOf(const std::string& name, const std::string& text) {
  const fs::path path = pnpba::test::scratchDir() / ("pnpba_bal_" + name);
  std::ofstream(path, std::ios::binary) << text;
  try {
    readBal(path.string());
  } catch (const Error& e) {
    const std::string msg = e.what();
    return msg.substr(path.string().size());  // drop the path prefix
  }
  return "";
}

TEST(BalReader, EveryMalformedFileGivesItsLine) {
  const std::string tail = "0 0 0 0 0 0 500 0 0\n0 0 -1\n";  // 1 camera, 1 point
  EXPECT_EQ(errorOf("ok", "1 1 1\n0 0 1.5 2.5\n" + tail), "");
  EXPECT_EQ(errorOf("empty", ""), ": empty file");
  EXPECT_EQ(errorOf("truncated", "1 1 1\n0 0 1.5 2.5\n0 0 0 0"),
            ": truncated: file ends before camera parameter");
  EXPECT_EQ(errorOf("negative", "1 1 1\n-1 0 1.5 2.5\n" + tail), ":2: negative camera index -1");
  EXPECT_EQ(errorOf("range", "1 1 1\n0 3 1.5 2.5\n" + tail),
            ":2: point index 3 out of range (1 points)");
  EXPECT_EQ(errorOf("nan", "1 1 1\n0 0 nan 2.5\n" + tail),
            ":2: observation u: non-finite value 'nan'");
  EXPECT_EQ(errorOf("nan-camera", "1 1 1\n0 0 1.5 2.5\n0 0 0 nan 0 0 500 0 0\n0 0 -1\n"),
            ":3: camera parameter: non-finite value 'nan'");
  EXPECT_EQ(errorOf("inf-point", "1 1 1\n0 0 1.5 2.5\n0 0 0 0 0 0 500 0 0\n0 -inf 1\n"),
            ":4: point coordinate: non-finite value '-inf'");
  // Counts no file of this size could hold are refused before anything is allocated.
  EXPECT_EQ(errorOf("huge", "1 1 999999999999\n0 0 1.5 2.5\n" + tail),
            ":1: header counts 1 1 999999999999 need more values than the file holds");
  EXPECT_EQ(errorOf("counts", "1 1 0\n" + tail),
            ":1: header counts must be positive (cameras points observations)");
  EXPECT_EQ(errorOf("garbage", std::string("1 1 1\n0 0 1.5 2.5\n\x01\x02\xff\n")),
            ":3: camera parameter: '?"
            "?"
            "?' is not a number");
  EXPECT_EQ(errorOf("trailing", "1 1 1\n0 0 1.5 2.5\n" + tail + "7\n"),
            ":5: trailing data after the last point: '7'");
  // Two cameras declared, the second never observed (its parameters are there).
  EXPECT_EQ(errorOf("unused", "2 1 1\n0 0 1.5 2.5\n0 0 0 0 0 0 500 0 0\n" + tail),
            ": camera 1 has no observation");
}

}  // namespace
}  // namespace pnpba
