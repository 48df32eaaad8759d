// The commonest edge's normal-equation kernels (quadratic_form.h): both builds against the terms
// summed by hand, and the AVX2 build against the baseline to the bit, since the solver must give
// the same answer on every CPU; and a graph solved with the kernels against the same graph with an
// information matrix that sends it down the generic path.
#include "pnpba/optimize/quadratic_form.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <array>
#include <cstring>
#include <random>
#include <tuple>

#include "pnpba/core/cpu_features.h"
#include "pnpba/optimize/edge_project_xyz2uv.h"
#include "pnpba/optimize/sparse_optimizer.h"
#include "pnpba/optimize/vertex_point_xyz.h"
#include "pnpba/optimize/vertex_se3_expmap.h"
#include "quadratic_form_kernels.h"

namespace pnpba {
namespace {

// One edge's inputs and the blocks it adds to (which start non-zero, as in a graph's second edge).
struct Terms {
  double w = 1;
  std::array<double, 6> J_p{};
  std::array<double, 12> J_c{};
  std::array<double, 2> e{};
  std::array<double, 9> H_pp{};
  std::array<double, 3> b_p{};
  std::array<double, 36> H_cc{};
  std::array<double, 6> b_c{};
  std::array<double, 18> H_cp{};
};

Terms randomTerms(std::mt19937_64* rng) {
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> scale(-6, 6);
  Terms t;
  t.w = std::exp(g(*rng));
  auto fill = [&](auto* a) {
    for (double& v : *a) v = g(*rng) * std::pow(10.0, scale(*rng));
  };
  fill(&t.J_p), fill(&t.J_c), fill(&t.e), fill(&t.H_pp), fill(&t.b_p), fill(&t.H_cc);
  fill(&t.b_c), fill(&t.H_cp);
  return t;
}

void pointPose(internal::PointPoseQuadraticForm kernel, Terms* t) {
  kernel(t->w, t->J_p.data(), t->J_c.data(), t->e.data(), t->H_pp.data(), t->b_p.data(),
         t->H_cc.data(), t->b_c.data(), t->H_cp.data());
}

// got == start + sign * w (A(0, i) B(0, j) + A(1, i) B(1, j)) for every entry of a rows x cols
// block (column-major), to rounding; A and B are 2 x n, column-major.
void expectTerms(const double* got, const double* start, int rows, int cols, double sign, double w,
                 const double* A, const double* B) {
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < cols; ++j) {
      const double term = sign * w * (A[2 * i] * B[2 * j] + A[2 * i + 1] * B[2 * j + 1]);
      const double want = start[rows * j + i] + term;
      EXPECT_LE(std::abs(got[rows * j + i] - want),
                1e-12 * (std::abs(start[rows * j + i]) + std::abs(term)))
          << "entry " << i << ", " << j;
    }
  }
}

TEST(QuadraticForm, BaselineEqualsTheTermsSummedByHand) {
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    Terms t = randomTerms(&rng);
    const Terms s = t;
    pointPose(internal::baseline::addPointPoseQuadraticForm, &t);
    const double* Jp = s.J_p.data();
    const double* Jc = s.J_c.data();
    const double* e = s.e.data();  // a 2 x 1 "matrix"
    expectTerms(t.H_cc.data(), s.H_cc.data(), 6, 6, 1, s.w, Jc, Jc);
    expectTerms(t.H_cp.data(), s.H_cp.data(), 6, 3, 1, s.w, Jc, Jp);
    expectTerms(t.b_c.data(), s.b_c.data(), 6, 1, -1, s.w, Jc, e);
    expectTerms(t.H_pp.data(), s.H_pp.data(), 3, 3, 1, s.w, Jp, Jp);
    expectTerms(t.b_p.data(), s.b_p.data(), 3, 1, -1, s.w, Jp, e);
  }
}

TEST(QuadraticForm, Avx2KernelsEqualTheBaselineToTheBit) {
  if (!cpuHasAvx2Fma()) GTEST_SKIP() << "this CPU has no AVX2";
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 2000; ++trial) {
    const Terms start = randomTerms(&rng);
    Terms a = start, b = start;
    pointPose(internal::baseline::addPointPoseQuadraticForm, &a);
    pointPose(internal::avx2::addPointPoseQuadraticForm, &b);
    EXPECT_EQ(std::memcmp(&a, &b, sizeof a), 0) << "trial " << trial;
    Terms c = start, d = start;
    internal::baseline::addPointQuadraticForm(c.w, c.J_p.data(), c.e.data(), c.H_pp.data(),
                                              c.b_p.data());
    internal::avx2::addPointQuadraticForm(d.w, d.J_p.data(), d.e.data(), d.H_pp.data(),
                                          d.b_p.data());
    EXPECT_EQ(std::memcmp(&c, &d, sizeof c), 0) << "trial " << trial;
  }
}

// Two cameras (the first fixed) and 40 points: with the identity information the edges take the
// kernels; with 1e-300 off the diagonal (not the identity, so the generic code, and a weight far
// below any rounding of the rest) they take the generic path. Both solve to the same pose.
TEST(QuadraticForm, AGraphSolvesAsOnTheGenericPath) {
  auto solve = [](bool generic) {
    std::mt19937_64 rng(9);
    std::normal_distribution<double> g;
    SparseOptimizer optimizer;
    auto* camera1 = new VertexSE3Expmap();
    camera1->setId(0);
    camera1->setFixed(true);
    optimizer.addVertex(camera1);
    auto* camera2 = new VertexSE3Expmap();
    camera2->setId(1);
    Vector6d xi;
    xi << 0.02, -0.03, 0.01, 0.3, 0.05, -0.02;
    const SE3Quat truth = SE3Quat::exp(xi);
    camera2->setEstimate(SE3Quat::exp(Vector6d::Constant(0.01)) * truth);
    optimizer.addVertex(camera2);
    auto* parameters = new CameraParameters(500, Eigen::Vector2d(320, 240), 0);
    parameters->setId(0);
    optimizer.addParameter(parameters);
    int id = 2, edge_id = 0;
    for (int i = 0; i < 40; ++i) {
      const Eigen::Vector3d X(g(rng), g(rng), 4 + g(rng));
      auto* point = new VertexPointXYZ();
      point->setId(id++);
      point->setMarginalized(true);
      point->setEstimate(X + 0.05 * Eigen::Vector3d(g(rng), g(rng), g(rng)));
      optimizer.addVertex(point);
      for (const auto& [camera, T] :
           {std::pair<VertexSE3Expmap*, SE3Quat>{camera1, SE3Quat()}, {camera2, truth}}) {
        auto* e = new EdgeProjectXYZ2UV();
        e->setId(edge_id++);
        e->setVertex(0, point);
        e->setVertex(1, camera);
        e->setParameterId(0, 0);
        const Eigen::Vector3d P = T.map(X);
        e->setMeasurement(Eigen::Vector2d(500 * P.x() / P.z() + 320, 500 * P.y() / P.z() + 240) +
                          0.5 * Eigen::Vector2d(g(rng), g(rng)));
        Eigen::Matrix2d information = Eigen::Matrix2d::Identity();
        if (generic) information(0, 1) = information(1, 0) = 1e-300;
        e->setInformation(information);
        optimizer.addEdge(e);
      }
    }
    optimizer.initializeOptimization();
    optimizer.computeActiveErrors();
    const double chi2_start = optimizer.activeChi2();
    optimizer.optimize(20);
    return std::tuple{camera2->estimate(), chi2_start, optimizer.activeChi2()};
  };
  const auto [kernels, chi2_start, chi2_end] = solve(false);
  const SE3Quat generic = std::get<0>(solve(true));
  EXPECT_LT((kernels.inverse() * generic).log().norm(), 1e-12);
  // It solved: 0.25 px^2 of noise on 160 coordinates, less the 126 unknowns' share.
  EXPECT_GT(chi2_start, 1000.0);
  EXPECT_LT(chi2_end, 40.0);
}

}  // namespace
}  // namespace pnpba
