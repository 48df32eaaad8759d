// The dedicated BAL solver (solver "pnpba"): its analytic Snavely Jacobians against central
// differences; on generated problems with ground truth, the same minimum as an independent
// Ceres autodiff solve, the same per-iteration costs as Ceres's LM (same schedule, same model),
// the three linear solvers agreeing, robust losses, and results independent of the thread count.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>

#include "camera_row.h"
#include "dense_cholesky.h"
#include "pnpba/bal/bal_solver.h"
#include "pnpba/bal/bal_synthetic.h"
#include "pnpba/core/cpu_features.h"
#include "pnpba/core/error.h"
#include "reduced_camera_system.h"
#include "shared_data.h"
#include "snavely_autodiff.h"
#include "snavely_projection.h"

namespace pnpba {
namespace {

using bal_detail::Matrix23;
using bal_detail::Matrix29;

TEST(SnavelyProjection, JacobiansMatchCentralDifferences) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 60; ++trial) {
    // Rotations from 0 (the first-order branch) to ~2.5 rad; points 2-20 m in front.
    const double scale = trial < 5 ? 0.0 : trial < 10 ? 1e-11 : 1.5;
    double camera[9] = {scale * u(rng), scale * u(rng),     scale * u(rng), u(rng),       u(rng),
                        u(rng),         500 + 100 * u(rng), 0.1 * u(rng),   0.01 * u(rng)};
    Eigen::Matrix3d R;
    bal_detail::rotationAndLeftJacobian(Eigen::Map<Eigen::Vector3d>(camera), &R, nullptr);
    // A point in front: camera frame P = (x, y, -z) mapped back to the world.
    const Eigen::Vector3d P(u(rng), u(rng), -(2 + 9 * (u(rng) + 1)));
    Eigen::Vector3d X = R.transpose() * (P - Eigen::Map<Eigen::Vector3d>(camera + 3));
    Matrix29 Jc;
    Matrix23 Jp;
    bal_detail::snavelyResidual(camera, X.data(), 3, 4, &Jc, &Jp);
    for (int k = 0; k < 12; ++k) {
      double* value = k < 9 ? &camera[k] : &X[k - 9];
      const double h = 1e-6 * std::max(1.0, std::abs(*value));
      const double saved = *value;
      *value = saved + h;
      const Eigen::Vector2d plus = bal_detail::snavelyResidual(camera, X.data(), 3, 4);
      *value = saved - h;
      const Eigen::Vector2d minus = bal_detail::snavelyResidual(camera, X.data(), 3, 4);
      *value = saved;
      const Eigen::Vector2d numeric = (plus - minus) / (2 * h);
      const Eigen::Vector2d analytic =
          k < 9 ? Eigen::Vector2d(Jc.col(k)) : Eigen::Vector2d(Jp.col(k - 9));
      EXPECT_LT((numeric - analytic).norm(), 1e-6 * std::max(1.0, analytic.norm()))
          << "trial " << trial << " parameter " << k;
    }
    // The solver keeps no point Jacobian: a point enters through P = R X + t, so its Jacobian is
    // the translation's times R.
    EXPECT_LE((Jp - Jc.middleCols<3>(3) * R).norm(), 1e-12 * Jp.norm()) << "trial " << trial;
  }
}

// The reduced camera system's pattern: for each camera the later cameras it shares a point with,
// against every pair of observations of every point checked directly.
TEST(ReducedCameraSystem, PartnersAreTheCamerasSharingAPoint) {
  BalSyntheticOptions o;
  o.cameras = 30, o.points = 200, o.observations_per_point = 3;
  const BalProblem p = generateBalProblem(o).start;
  const bal_detail::ObservationIndex index(p);
  std::vector<std::vector<char>> shares(p.num_cameras, std::vector<char>(p.num_cameras, 0));
  for (const BalObservation& x : p.observations) {
    for (const BalObservation& y : p.observations) {
      if (x.point == y.point) shares[x.camera][y.camera] = 1;
    }
  }
  const std::vector<std::vector<int>>& partners = index.camera_partners;
  ASSERT_EQ(static_cast<int>(partners.size()), p.num_cameras);
  // The same in bands of 1, 7 and 64 rows (the scratch bits a large problem is limited to).
  for (size_t bits : {64, 7 * 64, 64 * 64}) {
    EXPECT_EQ(bal_detail::cameraPartners(p, index, bits), partners) << bits << " bits";
  }
  size_t blocks = 0;
  for (int a = 0; a < p.num_cameras; ++a) {
    std::vector<int> expected;
    for (int b = a + 1; b < p.num_cameras; ++b) {
      if (shares[a][b]) expected.push_back(b);
    }
    EXPECT_EQ(partners[a], expected) << "camera " << a;
    blocks += expected.size();
  }
  EXPECT_GT(blocks, 0u);
  EXPECT_LT(blocks, static_cast<size_t>(p.num_cameras * (p.num_cameras - 1) / 2));  // not all
  EXPECT_DOUBLE_EQ(bal_detail::reducedSystemDensity(p, index),
                   (p.num_cameras + blocks) / (p.num_cameras * (p.num_cameras + 1) / 2.0));
}

// The dense solve, in both builds of its Cholesky and on one and two threads: S x = b to
// round-off against an independent LU solve, the same bits on either thread count, on S from a
// product (positive definite) and on one that is not (also where only a later block fails).
TEST(DenseCholesky, BothBuildsSolveAndRejectIndefinite) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> g;
  for (int n : {9, 64, 441, 700}) {
    Eigen::MatrixXd A(n, n);
    for (int i = 0; i < A.size(); ++i) A.data()[i] = g(rng);
    const Eigen::MatrixXd S = A * A.transpose() + Eigen::MatrixXd::Identity(n, n);
    Eigen::VectorXd b(n);
    for (int i = 0; i < n; ++i) b[i] = g(rng);
    const Eigen::VectorXd expected = S.partialPivLu().solve(b);
    const bool avx2 = cpuHasAvx2Fma();
    auto solve = [&](int build, auto* upper, auto* x, int threads) {
      return build == 0 ? bal_detail::solveDenseSpd(upper->data(), n, x->data(), threads)
                        : bal_detail::avx2::solveDenseSpd(upper->data(), n, x->data(), threads);
    };
    for (int build = 0; build < (avx2 ? 2 : 1); ++build) {
      Eigen::VectorXd first;
      for (int threads : {1, 2}) {
        Eigen::MatrixXd upper = S.triangularView<Eigen::Upper>();  // the lower triangle unread
        Eigen::VectorXd x = b;
        ASSERT_TRUE(solve(build, &upper, &x, threads)) << "n " << n << " build " << build;
        EXPECT_LT((x - expected).norm(), 1e-9 * expected.norm()) << "n " << n << " build " << build;
        if (threads == 1) first = x;
        EXPECT_EQ(x, first) << "n " << n << " build " << build << ": threads change the result";
      }
      Eigen::MatrixXf upper_f = S.cast<float>().triangularView<Eigen::Upper>();
      Eigen::VectorXf x_f = b.cast<float>();
      ASSERT_TRUE(solve(build, &upper_f, &x_f, 2));
      EXPECT_LT((x_f.cast<double>() - expected).norm(), 1e-2 * expected.norm());
      for (int threads : {1, 2}) {
        Eigen::MatrixXd indefinite = -S;
        Eigen::VectorXd x = b;
        EXPECT_FALSE(solve(build, &indefinite, &x, threads));
        // Positive definite but for its last diagonal entry: the last block's factorisation fails.
        Eigen::MatrixXd last = S;
        last(n - 1, n - 1) = -1;
        x = b;
        EXPECT_FALSE(solve(build, &last, &x, threads)) << "n " << n << " build " << build;
      }
    }
  }
}

// A block row of the reduced camera system, in both builds of its kernel, against
// S_ab = U_a [a = b] - sum over points of W_i V^-1 W_j^T (i: a's observations of the point, j:
// b's) and rhs_a = -g_a + sum W_i V^-1 g_p, with W_i = Jc_i^T Jp_i formed explicitly.
TEST(CameraRow, BothBuildsEqualTheSchurComplementFormedDirectly) {
  BalSyntheticOptions o;
  o.cameras = 8, o.points = 60, o.observations_per_point = 3;
  const BalProblem p = generateBalProblem(o).start;
  const bal_detail::ObservationIndex index(p);
  std::mt19937_64 rng(4);
  std::normal_distribution<double> g;
  auto randomArray = [&](size_t n) {
    std::vector<double> v(n);
    for (double& x : v) x = g(rng);
    return v;
  };
  const size_t n_obs = p.observations.size();
  const std::vector<double> Jc = randomArray(18 * n_obs), point_map = randomArray(9 * o.cameras),
                            point_scale = randomArray(3 * o.points),
                            V_inverse = randomArray(9 * o.points), g_p = randomArray(3 * o.points),
                            g_c = randomArray(9 * o.cameras), U = randomArray(81 * o.cameras);
  const bal_detail::CameraRowData data{p.observations.data(),
                                       index.camera_start.data(),
                                       index.by_camera.data(),
                                       index.point_start.data(),
                                       index.by_point.data(),
                                       index.camera_by_point.data(),
                                       Jc.data(),
                                       point_map.data(),
                                       point_scale.data(),
                                       V_inverse.data(),
                                       g_p.data(),
                                       g_c.data(),
                                       U.data()};
  using Matrix9 = Eigen::Matrix<double, 9, 9>;
  using Matrix93 = Eigen::Matrix<double, 9, 3>;
  auto W = [&](size_t i) -> Matrix93 {
    const BalObservation& x = p.observations[i];
    const Eigen::Map<const Matrix29> J(Jc.data() + 18 * i);
    const Matrix23 jp =
        J.middleCols<3>(3) * Eigen::Map<const Eigen::Matrix3d>(point_map.data() + 9 * x.camera) *
        Eigen::Map<const Eigen::Vector3d>(point_scale.data() + 3 * x.point).asDiagonal();
    return J.transpose() * jp;
  };
  const std::vector<std::vector<int>> partners = bal_detail::cameraPartners(p, index);
  const bool avx2 = cpuHasAvx2Fma();
  for (int a = 0; a < o.cameras; ++a) {
    std::vector<int> cameras = {a};
    cameras.insert(cameras.end(), partners[a].begin(), partners[a].end());
    std::vector<int> slot(o.cameras, -1);
    for (size_t k = 0; k < cameras.size(); ++k) slot[cameras[k]] = static_cast<int>(k);
    std::vector<Matrix9> expected(cameras.size(), Matrix9::Zero());
    expected[0] = Eigen::Map<const Matrix9>(U.data() + 81 * a);
    Eigen::Matrix<double, 9, 1> expected_rhs =
        -Eigen::Map<const Eigen::Matrix<double, 9, 1>>(g_c.data() + 9 * a);
    for (size_t i = 0; i < n_obs; ++i) {
      if (p.observations[i].camera != a) continue;
      const int q = p.observations[i].point;
      const Eigen::Map<const Eigen::Matrix3d> Vinv(V_inverse.data() + 9 * q);
      expected_rhs += W(i) * Vinv * Eigen::Map<const Eigen::Vector3d>(g_p.data() + 3 * q);
      for (size_t j = 0; j < n_obs; ++j) {
        const int b = p.observations[j].camera;
        if (p.observations[j].point != q || b < a) continue;
        expected[slot[b]] -= W(i) * Vinv * W(j).transpose();
      }
    }
    for (int build = 0; build < (avx2 ? 2 : 1); ++build) {
      // The kernel's blocks: 12 x 9 each (9 x 9 and three rows of padding), 32-byte aligned.
      std::vector<double> storage(bal_detail::kPaddedBlock * cameras.size() + 4, NAN);
      std::vector<double> rhs(9, NAN);
      double* rows = storage.data();
      while (reinterpret_cast<std::uintptr_t>(rows) % 32 != 0) ++rows;
      (build == 0 ? bal_detail::buildCameraRow : bal_detail::avx2::buildCameraRow)(
          data, a, slot.data(), static_cast<int>(cameras.size()), rows, rhs.data());
      for (size_t k = 0; k < cameras.size(); ++k) {
        const Eigen::Map<const Matrix9, 0, Eigen::OuterStride<12>> got(
            rows + bal_detail::kPaddedBlock * k);
        EXPECT_LT((got - expected[k]).norm(), 1e-12 * (1 + expected[k].norm()))
            << "camera " << a << " block " << cameras[k] << " build " << build;
      }
      EXPECT_LT((Eigen::Map<const Eigen::Matrix<double, 9, 1>>(rhs.data()) - expected_rhs).norm(),
                1e-12 * (1 + expected_rhs.norm()))
          << "camera " << a << " build " << build;
    }
  }
}

BalSyntheticProblem smallProblem(uint64_t seed = 5, double perturbation = 1) {
  BalSyntheticOptions o;
  o.cameras = 12, o.points = 400, o.observations_per_point = 4, o.noise_px = 0.5, o.seed = seed;
  o.start.seed = seed + 1;
  o.start.rotation_sigma *= perturbation, o.start.translation_sigma *= perturbation;
  o.start.point_sigma *= perturbation;
  return generateBalProblem(o);
}

BalSolveSummary solvePnpba(BalProblem& p, const std::string& linear_solver, int threads = 1,
                           const std::string& robust = "none") {
  BalSolveOptions o;
  o.linear_solver = linear_solver, o.threads = threads, o.robust = robust;
  return solveBal(p, o);
}

TEST(SchurLmSolver, ReachesTheMinimumOfAnIndependentCeresSolveAndBeatsTheTruth) {
  const BalSyntheticProblem g = smallProblem();
  BalProblem ours = g.start, theirs = g.start;
  const BalSolveSummary s = solvePnpba(ours, "dense");
  const test::AutodiffSolve c = test::solveWithCeresAutodiff(theirs, 50, 1);
  ASSERT_TRUE(s.ok) << s.termination;
  EXPECT_NEAR(s.initial_cost, c.initial_cost, 1e-9 * c.initial_cost);
  EXPECT_NEAR(s.final_cost, c.final_cost, 1e-6 * c.final_cost);
  // A least-squares minimum is at or below the cost of the true parameters, and with 0.5 px
  // noise the RMS is near 0.5 px (fewer residuals than unknowns would take it lower).
  EXPECT_LE(s.final_cost, g.truth.cost() * (1 + 1e-9));
  EXPECT_GT(s.rms_px_final, 0.3);
  EXPECT_LT(s.rms_px_final, 0.6);
  EXPECT_NEAR(ours.cost(), s.final_cost, 1e-9 * s.final_cost);
  // Without a robust loss the RMS comes from the solver's own cost: it must be the problem's.
  EXPECT_NEAR(s.rms_px_initial, g.start.rmsPixels(), 1e-9 * g.start.rmsPixels());
  EXPECT_NEAR(s.rms_px_final, ours.rmsPixels(), 1e-9 * s.rms_px_final);
}

// The graph engine's own LM on the BAL graph (9-dof cameras: its elimination for any vertex
// sizes, not the 6/3 kernel) reaches the dedicated solver's minimum.
TEST(SchurLmSolver, GraphEngineOnNineDofCamerasReachesTheSameMinimum) {
  const BalSyntheticProblem g = smallProblem();
  BalProblem ours = g.start, graph = g.start;
  const BalSolveSummary s = solvePnpba(ours, "dense");
  BalSolveOptions o;
  o.solver = "native";
  o.iterations = 100;
  const BalSolveSummary n = solveBal(graph, o);
  ASSERT_TRUE(s.ok && n.ok) << s.termination << " / " << n.termination;
  EXPECT_NEAR(n.initial_cost, s.initial_cost, 1e-9 * s.initial_cost);
  EXPECT_NEAR(n.final_cost, s.final_cost, 1e-6 * s.final_cost);
  EXPECT_LT(n.final_cost, 0.5 * n.initial_cost);
}

TEST(SchurLmSolver, FollowsCeresIterationByIteration) {
  // Same model, same damping and trust-region schedule: the per-iteration costs agree. A start
  // far enough off to take several iterations.
  const BalSyntheticProblem g = smallProblem(9, 15);
  BalProblem ours = g.start, theirs = g.start;
  const BalSolveSummary s = solvePnpba(ours, "dense");
  const test::AutodiffSolve c = test::solveWithCeresAutodiff(theirs, 50, 1);
  const size_t n = std::min<size_t>(6, std::min(s.table.size(), c.all_costs.size()));
  ASSERT_GE(n, 4u);
  for (size_t k = 0; k < n; ++k) {
    EXPECT_NEAR(s.table[k].cost, c.all_costs[k], 1e-6 * c.all_costs[k]) << "iteration " << k;
  }
}

TEST(SchurLmSolver, DenseSparseAndConjugateGradientsAgree) {
  const BalSyntheticProblem g = smallProblem(11);
  BalProblem dense = g.start, sparse = g.start, cg = g.start;
  const double d = solvePnpba(dense, "dense").final_cost;
  const double s = solvePnpba(sparse, "sparse").final_cost;
  const double c = solvePnpba(cg, "cg").final_cost;
  EXPECT_NEAR(s, d, 1e-9 * d);  // both exact: the same steps
  EXPECT_NEAR(c, d, 1e-5 * d);  // inexact steps, the same minimum
}

TEST(SchurLmSolver, SinglePrecisionFactorsReachTheSameMinimum) {
  const BalSyntheticProblem g = smallProblem(19, 5);
  for (const char* linear : {"dense", "sparse"}) {
    BalProblem exact = g.start, single = g.start;
    const double d = solvePnpba(exact, linear).final_cost;
    BalSolveOptions o;
    o.linear_solver = linear, o.single_precision = true;
    const BalSolveSummary s = solveBal(single, o);
    EXPECT_TRUE(s.single_precision);
    EXPECT_NEAR(s.final_cost, d, 1e-6 * d) << linear;
  }
  BalSolveOptions ceres;
  ceres.solver = "ceres-dense_schur", ceres.single_precision = true;
  EXPECT_EQ(ceres.validate(), "single precision needs the pnpba solver");
}

TEST(SchurLmSolver, ResultsAreBitIdenticalForAnyThreadCount) {
  const BalSyntheticProblem g = smallProblem(13);
  for (const char* linear : {"dense", "sparse", "cg"}) {
    BalProblem one = g.start, two = g.start;
    solvePnpba(one, linear, 1);
    solvePnpba(two, linear, 2);
    EXPECT_EQ(one.cameras, two.cameras) << linear;
    EXPECT_EQ(one.points, two.points) << linear;
  }
}

TEST(SchurLmSolver, RobustLossesMatchCeres) {
  BalSyntheticProblem g = smallProblem(17);
  // Every 20th observation 40 px off: outliers the losses must discount.
  for (size_t i = 0; i < g.start.observations.size(); i += 20) g.start.observations[i].u += 40;
  for (const char* loss : {"huber", "cauchy"}) {
    BalProblem ours = g.start, theirs = g.start;
    const BalSolveSummary s = solvePnpba(ours, "dense", 1, loss);
    const test::AutodiffSolve c =
        test::solveWithCeresAutodiff(theirs, 50, 1, ceres::DENSE_SCHUR, 1e-6, {}, loss);
    EXPECT_NEAR(s.initial_cost, c.initial_cost, 1e-9 * c.initial_cost) << loss;
    EXPECT_NEAR(s.final_cost, c.final_cost, 1e-5 * c.final_cost) << loss;
  }
}

TEST(SchurLmSolver, LadybugReachesCeressFinalCost) {
  PNPBA_REQUIRE_SHARED_DATA();
  BalProblem ours = readBal(test::sharedData("bal/problem-49-7776-pre.txt"));
  BalProblem theirs = ours;
  const BalSolveSummary s = solvePnpba(ours, "auto", 2);
  const test::AutodiffSolve c = test::solveWithCeresAutodiff(theirs, 50, 2);
  EXPECT_EQ(s.linear_solver, "dense");
  EXPECT_LE(s.final_cost, c.final_cost * 1.001);  // the "same final cost to 0.1 %"
}

TEST(SchurLmSolver, InvalidOptionsAreNamed) {
  BalProblem p = smallProblem().start;
  BalSolveOptions o;
  o.linear_solver = "magic";
  EXPECT_THROW(solveBal(p, o), Error);
  o = BalSolveOptions{};
  o.solver = "dense_schur";  // the old name: Ceres's solvers are now ceres-*
  EXPECT_NE(o.validate().find("ceres-dense_schur"), std::string::npos);
}

}  // namespace
}  // namespace pnpba
