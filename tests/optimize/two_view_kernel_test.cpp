// The native LM's two-view kernel (optimize/src/two_view_kernel.h) against the general path on
// the same graphs: random two-view problems with either edge type, informations w I, camera 1
// fixed at the identity or elsewhere, with or without it, starts off enough for LM to reject
// trials. Every solve must take the same number of iterations to the same chi2, pose, points and
// covariance to round-off; graphs the kernel does not compute must go to the general path.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "pnpba/core/cpu_features.h"
#include "pnpba/optimize/edge_project_xyz2uv.h"
#include "pnpba/optimize/edge_se3_project_xyz.h"
#include "pnpba/optimize/robust_kernel.h"
#include "pnpba/optimize/sparse_optimizer.h"
#include "random_poses.h"
#include "two_view_camera.h"
#include "two_view_loops.h"

namespace pnpba {
namespace {

struct Scene {
  bool camera1 = true;            // camera 1 observes every point too (a fixed vertex)
  bool camera1_identity = true;   // ... from the identity, else from a random fixed pose
  bool camera3 = false;           // a third camera, fixed, observes them too: the scale is fixed
  bool huber = false;             // a robust kernel on one edge
  bool second_look = false;       // one point observed twice by camera 2
  bool second_free_pose = false;  // camera 1 free as well
};

struct Solved {
  OptimizationSummary summary;
  SE3Quat T;
  std::vector<Eigen::Vector3d> points;
  Eigen::MatrixXd covariance;
  bool covariance_ok = false;
  std::vector<Eigen::Vector2d> errors;  // every edge's, as optimize() leaves them
  std::vector<Eigen::Vector2d> fresh;   // ... and recomputed
  int most_trials = 0;                  // of any iteration: above 1, LM rejected a step
};

Solved solve(unsigned seed, const Scene& scene, bool kernel) {
  test::RandomScene rnd(seed);
  SparseOptimizer opt;
  opt.setSolverBackend(SolverBackend::kNative);
  opt.options().two_view_kernel = kernel;
  auto* camera = new CameraParameters(520.9, Eigen::Vector2d(325.1, 249.7), 0);
  camera->setId(0);
  opt.addParameter(camera);
  const PinholeIntrinsics K{517.3, 516.5, 318.6, 255.3};
  const SE3Quat T1 = scene.camera1_identity ? SE3Quat() : rnd.pose(0.1, 0.2);
  const SE3Quat T2 = rnd.pose(0.3, 0.6) * T1;
  auto* pose = new VertexSE3Expmap();
  pose->setId(0);
  Vector6d twist;
  for (int j = 0; j < 6; ++j) twist[j] = rnd.uniform(-0.1, 0.1);
  pose->setEstimate(SE3Quat::exp(twist) * T2);
  opt.addVertex(pose);
  VertexSE3Expmap* fixed = nullptr;
  if (scene.camera1) {
    fixed = new VertexSE3Expmap();
    fixed->setId(1);
    fixed->setFixed(!scene.second_free_pose);
    fixed->setEstimate(T1);
    opt.addVertex(fixed);
  }
  const SE3Quat T3 = rnd.pose(0.2, 0.4) * T1;
  VertexSE3Expmap* third = nullptr;
  if (scene.camera3) {
    third = new VertexSE3Expmap();
    third->setId(2);
    third->setFixed(true);
    third->setEstimate(T3);
    opt.addVertex(third);
  }
  const int n = 40 + static_cast<int>(rnd.uniform(0, 60));
  std::vector<Edge*> edges;
  auto observe = [&](VertexPointXYZ* p, VertexSE3Expmap* cam, const SE3Quat& T,
                     const Eigen::Vector3d& X, int i) {
    const Eigen::Vector3d P = T.map(X);
    const double w = rnd.uniform(0.25, 4.0);
    Eigen::Vector2d uv;
    BaseBinaryEdge<2, Eigen::Vector2d, VertexPointXYZ, VertexSE3Expmap>* e;
    if (i % 3 == 0) {
      auto* projection = new EdgeProjectXYZ2UV();
      projection->setParameterId(0, 0);
      uv = camera->cam_map(P);
      e = projection;
    } else {
      auto* pinhole = new EdgeSE3ProjectXYZ();
      pinhole->fx = K.fx, pinhole->fy = K.fy, pinhole->cx = K.cx, pinhole->cy = K.cy;
      uv = K.project(P);
      e = pinhole;
    }
    e->setId(static_cast<int>(edges.size()));
    e->setVertex(0, p);
    e->setVertex(1, cam);
    e->setMeasurement(uv + Eigen::Vector2d(rnd.normal(0.7), rnd.normal(0.7)));
    e->setInformation(w * Eigen::Matrix2d::Identity());
    opt.addEdge(e);
    edges.push_back(e);
  };
  std::vector<VertexPointXYZ*> points;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d X = rnd.pointInFront(T1, 2.0, 6.0);
    auto* p = new VertexPointXYZ();
    p->setId(3 + i);
    p->setMarginalized(true);
    p->setEstimate(X + Eigen::Vector3d(rnd.normal(0.05), rnd.normal(0.05), rnd.normal(0.05)));
    opt.addVertex(p);
    points.push_back(p);
    observe(p, pose, T2, X, i);
    if (scene.camera1) observe(p, fixed, T1, X, i + 1);
    if (scene.camera3) observe(p, third, T3, X, i + 2);
    if (scene.second_look && i == 0) observe(p, pose, T2, X, i + 2);
  }
  if (scene.huber) edges[0]->setRobustKernel(new RobustKernelHuber(2.0));
  opt.initializeOptimization();
  Solved s;
  opt.setIterationCallback([&s](const IterationStats& it) {
    s.most_trials = std::max(s.most_trials, it.levenberg_trials);
  });
  opt.optimize(50);
  s.summary = opt.summary();
  s.T = pose->estimate();
  for (const VertexPointXYZ* p : points) s.points.push_back(p->estimate());
  for (Edge* e : edges) s.errors.emplace_back(e->errorData()[0], e->errorData()[1]);
  for (Edge* e : edges) {
    e->computeError();
    s.fresh.emplace_back(e->errorData()[0], e->errorData()[1]);
  }
  s.covariance_ok = opt.computeMarginalCovariance(0, &s.covariance);
  return s;
}

// posed: the graph fixes every direction (three views); otherwise the points can absorb the
// errors (one view) or the scale is free (two views), so only chi2 and the rotation are pinned
// and round-off moves the rest along the free directions.
void expectSameSolve(const Solved& a, const Solved& b, bool posed) {
  EXPECT_EQ(a.summary.iterations, b.summary.iterations);
  EXPECT_EQ(a.most_trials, b.most_trials);
  const double chi2 = b.summary.initial_chi2;
  EXPECT_NEAR(a.summary.initial_chi2, chi2, 1e-12 * chi2);
  EXPECT_NEAR(a.summary.final_chi2, b.summary.final_chi2, (posed ? 1e-12 : 1e-9) * chi2);
  const Vector6d d = (a.T * b.T.inverse()).log();
  EXPECT_LT(d.head<3>().norm(), posed ? 1e-10 : 1e-6) << d.transpose();
  if (!posed) return;
  EXPECT_LT(d.tail<3>().norm(), 1e-10) << d.transpose();
  for (size_t i = 0; i < a.points.size(); ++i) {
    EXPECT_LT((a.points[i] - b.points[i]).norm(), 1e-10 * b.points[i].norm()) << "point " << i;
  }
  ASSERT_TRUE(a.covariance_ok);
  ASSERT_TRUE(b.covariance_ok);
  EXPECT_LT((a.covariance - b.covariance).norm(), 1e-9 * b.covariance.norm());
}

TEST(TwoViewKernel, SolvesAsTheGeneralPathDoes) {
  int rejected = 0;
  for (unsigned seed = 1; seed <= 40; ++seed) {
    SCOPED_TRACE(seed);
    Scene scene;
    scene.camera1 = seed % 5 != 0;
    scene.camera1_identity = seed % 3 != 0;
    scene.camera3 = scene.camera1 && seed % 5 != 1;
    const Solved kernel = solve(seed, scene, true);
    const Solved general = solve(seed, scene, false);
    EXPECT_TRUE(kernel.summary.two_view_kernel);
    EXPECT_FALSE(general.summary.two_view_kernel);
    expectSameSolve(kernel, general, scene.camera3);
    // The edges hold the errors at the final estimates, as computeError() gives them.
    for (size_t e = 0; e < kernel.errors.size(); ++e) {
      EXPECT_LT((kernel.errors[e] - kernel.fresh[e]).norm(), 1e-9) << "edge " << e;
    }
    rejected += kernel.most_trials > 1 ? 1 : 0;
  }
  EXPECT_GT(rejected, 0);  // some solves went through rejected trials
}

TEST(TwoViewKernel, LeavesOtherGraphsToTheGeneralPath) {
  for (const Scene scene :
       {Scene{true, true, true, true, false, false}, Scene{true, true, true, false, true, false},
        Scene{true, false, true, false, false, true}}) {
    const Solved on = solve(7, scene, true);
    const Solved off = solve(7, scene, false);
    EXPECT_FALSE(on.summary.two_view_kernel);
    expectSameSolve(on, off, !scene.second_free_pose);
  }
}

// The loops' two builds (baseline and AVX2 + FMA) on the same random arrays: the same numbers to
// round-off (FMA and the vector width's order of summation apart). The solves above run the
// build this CPU has; this runs the other one too.
TEST(TwoViewKernel, BaselineAndAvx2LoopsAgree) {
  if (!cpuHasAvx2Fma()) GTEST_SKIP() << "no AVX2 + FMA on this CPU";
  test::RandomScene rnd(11);
  const size_t n = 37;  // not a multiple of the vector width
  auto arrays = [&](int count, double lo, double hi) {
    std::vector<std::vector<double>> a(count, std::vector<double>(n));
    for (auto& v : a) {
      for (double& x : v) x = rnd.uniform(lo, hi);
    }
    return a;
  };
  const two_view::CameraPose camera = cameraPoseOf(rnd.pose(0.5, 1.0));
  // Observations: points in front, pixels, intrinsics, weights.
  auto xyz = arrays(3, -1.0, 1.0);
  for (double& z : xyz[2]) z += 4.0;
  const auto pixels = arrays(2, 100.0, 500.0), focal = arrays(2, 400.0, 600.0);
  const auto centre = arrays(2, 300.0, 340.0), weight = arrays(1, 0.25, 4.0);
  struct Out {
    std::vector<std::vector<double>> v =
        std::vector<std::vector<double>>(14, std::vector<double>(37));
  };
  auto observations = [&](Out* out) {
    two_view::ObservationArrays o;
    o.n = n, o.x = xyz[0].data(), o.y = xyz[1].data(), o.z = xyz[2].data();
    o.mu = pixels[0].data(), o.mv = pixels[1].data(), o.fx = focal[0].data();
    o.fy = focal[1].data(), o.cx = centre[0].data(), o.cy = centre[1].data();
    o.w = weight[0].data();
    o.p0 = out->v[0].data(), o.p1 = out->v[1].data(), o.p2 = out->v[2].data();
    o.eu = out->v[3].data(), o.ev = out->v[4].data();
    for (int k = 0; k < 6; ++k) o.m[k] = out->v[5 + k].data();
    for (int k = 0; k < 3; ++k) o.g[k] = out->v[11 + k].data();
    return o;
  };
  Out base, fast;
  const double chi2_base = two_view::evaluateObservations(camera, observations(&base));
  const double chi2_fast = two_view::avx2::evaluateObservations(camera, observations(&fast));
  EXPECT_NEAR(chi2_base, chi2_fast, 1e-12 * chi2_base);
  for (int k = 0; k < 14; ++k) {
    for (size_t i = 0; i < n; ++i) {
      EXPECT_NEAR(base.v[k][i], fast.v[k][i], 1e-12 * (1 + std::abs(base.v[k][i])));
    }
  }
  // Points: the observations' terms, fixed cameras' sums (positive definite, of a pixel
  // observation's size, as another view's M is: a much smaller F leaves S as the small
  // difference of large terms in both builds), a step.
  auto F = arrays(6, -1e3, 1e3), f = arrays(3, -100.0, 100.0);
  for (size_t i = 0; i < n; ++i) F[0][i] += 1e4, F[3][i] += 1e4, F[5][i] += 1e4;
  struct Work {
    std::vector<double> h2 = std::vector<double>(6 * 37), b2 = std::vector<double>(3 * 37);
    std::vector<double> ninv = std::vector<double>(6 * 37);
    std::vector<double> terms = std::vector<double>(two_view::kEliminationTerms * 37);
    std::vector<double> bl = std::vector<double>(3 * 37), xl = std::vector<double>(3 * 37);
    double bp[6], S[36] = {}, rhs[6], max_diagonal = 0;
  };
  auto points = [&](const Out& o, Work* w) {
    two_view::PointArrays a;
    a.n = n;
    for (int k = 0; k < 3; ++k) {
      a.p[k] = o.v[k].data(), a.g[k] = o.v[11 + k].data(), a.f[k] = f[k].data();
      a.b2[k] = w->b2.data() + k * n;
    }
    for (int k = 0; k < 6; ++k) a.m[k] = o.v[5 + k].data();
    for (int k = 0; k < 6; ++k) {
      a.F[k] = F[k].data(), a.h2[k] = w->h2.data() + k * n, a.ninv[k] = w->ninv.data() + k * n;
    }
    a.terms = w->terms.data();
    return a;
  };
  const double xp[6] = {1e-3, -2e-3, 5e-4, 0.01, -0.02, 0.005};
  Work wb, wf;
  two_view::assemble(camera, points(base, &wb), wb.bl.data(), wb.bp);
  two_view::avx2::assemble(camera, points(base, &wf), wf.bl.data(), wf.bp);
  wb.max_diagonal = two_view::maxDiagonal(camera, points(base, &wb));
  wf.max_diagonal = two_view::avx2::maxDiagonal(camera, points(base, &wf));
  two_view::eliminate(points(base, &wb), 0.5, wb.S, wb.rhs);
  two_view::avx2::eliminate(points(base, &wf), 0.5, wf.S, wf.rhs);
  two_view::backSubstitute(camera, points(base, &wb), xp, wb.xl.data());
  two_view::avx2::backSubstitute(camera, points(base, &wf), xp, wf.xl.data());
  auto near = [](const double* a, const double* b, size_t count, const char* what) {
    double scale = 0;
    for (size_t i = 0; i < count; ++i) scale = std::max(scale, std::abs(a[i]));
    for (size_t i = 0; i < count; ++i) EXPECT_NEAR(a[i], b[i], 1e-12 * scale) << what << " " << i;
  };
  near(wb.bp, wf.bp, 6, "bp");
  near(wb.bl.data(), wf.bl.data(), wb.bl.size(), "bl");
  near(wb.h2.data(), wf.h2.data(), wb.h2.size(), "H2");
  near(&wb.max_diagonal, &wf.max_diagonal, 1, "max diagonal");
  near(wb.S, wf.S, 36, "S");
  near(wb.rhs, wf.rhs, 6, "rhs");
  near(wb.xl.data(), wf.xl.data(), wb.xl.size(), "xl");
}

// The RGB-D pair solver's evaluation loop (rgbd_pair.h's stereo errors with Huber) in both
// builds, with kernels that cut some errors and not others, and a pixel-only camera 2.
TEST(TwoViewKernel, BaselineAndAvx2StereoLoopsAgree) {
  if (!cpuHasAvx2Fma()) GTEST_SKIP() << "no AVX2 + FMA on this CPU";
  test::RandomScene rnd(12);
  const size_t n = 29;
  std::vector<std::vector<double>> in(19 + 3, std::vector<double>(n));
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) in[k][i] = rnd.uniform(100, 500);   // z1
    for (int k = 9; k < 12; ++k) in[k][i] = rnd.uniform(100, 500);  // z2
    for (int info : {3, 12}) {  // informations: positive definite, the second pixel-only at times
      in[info][i] = rnd.uniform(0.5, 2), in[info + 1][i] = rnd.uniform(-0.1, 0.1);
      in[info + 2][i] = rnd.uniform(-0.1, 0.1), in[info + 3][i] = rnd.uniform(0.5, 2);
      in[info + 4][i] = rnd.uniform(-0.1, 0.1), in[info + 5][i] = rnd.uniform(0.5, 2);
    }
    if (i % 3 == 0) in[14][i] = in[16][i] = in[17][i] = in[11][i] = 0;  // pixel-only camera 2
    in[18][i] = i % 4 == 0 ? 0.0 : rnd.uniform(1, 50);                  // camera 2's width
    in[19][i] = rnd.uniform(-1, 1), in[20][i] = rnd.uniform(-1, 1), in[21][i] = rnd.uniform(2, 6);
  }
  const two_view::CameraPose camera = cameraPoseOf(rnd.pose(0.3, 0.5));
  struct Out {
    std::vector<std::vector<double>> v =
        std::vector<std::vector<double>>(22, std::vector<double>(29));
  };
  auto arrays = [&](Out* out) {
    two_view::StereoPairArrays a;
    a.n = n, a.fx = 517.3, a.fy = 516.5, a.cx = 318.6, a.cy = 255.3, a.bf = 40.0, a.delta1 = 3.0;
    a.x = in[19].data(), a.y = in[20].data(), a.z = in[21].data();
    for (int k = 0; k < 3; ++k) a.z1[k] = in[k].data(), a.z2[k] = in[9 + k].data();
    for (int k = 0; k < 6; ++k) a.info1[k] = in[3 + k].data(), a.info2[k] = in[12 + k].data();
    a.delta2 = in[18].data();
    for (int k = 0; k < 3; ++k) {
      a.p[k] = out->v[k].data(), a.g[k] = out->v[3 + k].data(), a.f[k] = out->v[6 + k].data();
    }
    for (int k = 0; k < 6; ++k) a.m[k] = out->v[9 + k].data(), a.F[k] = out->v[15 + k].data();
    a.cost = out->v[21].data();
    return a;
  };
  Out base, fast;
  const double total_base = two_view::evaluateStereoPairs(camera, arrays(&base));
  const double total_fast = two_view::avx2::evaluateStereoPairs(camera, arrays(&fast));
  EXPECT_NEAR(total_base, total_fast, 1e-12 * total_base);
  for (int k = 0; k < 22; ++k) {
    double scale = 0;
    for (double x : base.v[k]) scale = std::max(scale, std::abs(x));
    for (size_t i = 0; i < n; ++i) EXPECT_NEAR(base.v[k][i], fast.v[k][i], 1e-12 * scale) << k;
  }
}

}  // namespace
}  // namespace pnpba
