// The native LM evaluates a trial step by linearising when every edge's linearizeOplus() leaves
// its error too (Edge::linearizationUpdatesError), so an accepted step needs no second pass. The
// same graphs solved with edges that do not say so take the other path (errors, then a fresh
// linearisation): every step, chi2 and estimate must be the same to the bit, through accepted
// and rejected trials alike.
#include <gtest/gtest.h>

#include <vector>

#include "pnpba/optimize/edge_se3_project_xyz.h"
#include "pnpba/optimize/sparse_optimizer.h"
#include "random_poses.h"

namespace pnpba {
namespace {

// The same edge, declaring that its linearisation leaves no error behind.
class EdgeWithoutErrorInLinearization : public EdgeSE3ProjectXYZ {
 public:
  bool linearizationUpdatesError() const override { return false; }
};

struct Solve {
  std::vector<double> chi2_per_iteration;
  std::vector<int> trials_per_iteration;
  std::vector<Vector7d> poses;
  std::vector<Eigen::Vector3d> points;
};

// Three cameras (the first fixed) and 60 points, 10 % of the pixels gross outliers, a Huber
// kernel, and a start far enough off that LM rejects some trials.
template <typename EdgeT>
Solve solve(unsigned seed) {
  test::RandomScene rnd(seed);
  SparseOptimizer opt;
  opt.setSolverBackend(SolverBackend::kNative);
  const PinholeIntrinsics K{517.3, 516.5, 318.6, 255.3};
  std::vector<SE3Quat> truth = {SE3Quat(), rnd.pose(0.2, 0.5), rnd.pose(0.2, 0.5)};
  std::vector<VertexSE3Expmap*> poses;
  for (int k = 0; k < 3; ++k) {
    auto* v = new VertexSE3Expmap();
    v->setId(k);
    v->setFixed(k == 0);
    Vector6d twist;
    for (int j = 0; j < 6; ++j) twist[j] = rnd.uniform(-0.15, 0.15);
    v->setEstimate(k == 0 ? truth[k] : SE3Quat::exp(twist) * truth[k]);
    opt.addVertex(v);
    poses.push_back(v);
  }
  std::vector<VertexPointXYZ*> points;
  for (int i = 0; i < 60; ++i) {
    const Eigen::Vector3d X = rnd.pointInFront(SE3Quat(), 2.0, 6.0);
    auto* p = new VertexPointXYZ();
    p->setId(3 + i);
    p->setMarginalized(true);
    p->setEstimate(X + Eigen::Vector3d(rnd.normal(0.2), rnd.normal(0.2), rnd.normal(0.2)));
    opt.addVertex(p);
    points.push_back(p);
    for (int k = 0; k < 3; ++k) {
      auto* e = new EdgeT();
      e->setVertex(0, p);
      e->setVertex(1, poses[k]);
      e->fx = K.fx, e->fy = K.fy, e->cx = K.cx, e->cy = K.cy;
      const double spread = rnd.uniform(0, 1) < 0.1 ? 30.0 : 0.7;
      e->setMeasurement(K.project(truth[k].map(X)) +
                        Eigen::Vector2d(rnd.normal(spread), rnd.normal(spread)));
      e->setRobustKernel(new RobustKernelHuber(2.0));
      opt.addEdge(e);
    }
  }
  Solve s;
  opt.setIterationCallback([&s](const IterationStats& it) {
    s.chi2_per_iteration.push_back(it.chi2);
    s.trials_per_iteration.push_back(it.levenberg_trials);
  });
  opt.initializeOptimization();
  opt.optimize(50);
  for (const VertexSE3Expmap* v : poses) s.poses.push_back(v->estimate().toVector());
  for (const VertexPointXYZ* p : points) s.points.push_back(p->estimate());
  return s;
}

TEST(TrialLinearization, SameStepsAsErrorsThenLinearization) {
  int rejected_trials = 0;
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const Solve fused = solve<EdgeSE3ProjectXYZ>(seed);
    const Solve separate = solve<EdgeWithoutErrorInLinearization>(seed);
    ASSERT_FALSE(fused.chi2_per_iteration.empty());
    EXPECT_EQ(fused.chi2_per_iteration, separate.chi2_per_iteration) << "seed " << seed;
    EXPECT_EQ(fused.trials_per_iteration, separate.trials_per_iteration) << "seed " << seed;
    EXPECT_EQ(fused.poses, separate.poses) << "seed " << seed;
    EXPECT_EQ(fused.points, separate.points) << "seed " << seed;
    for (int t : fused.trials_per_iteration) rejected_trials += t - 1;
  }
  EXPECT_GT(rejected_trials, 0) << "no graph exercised a rejected trial";
}

}  // namespace
}  // namespace pnpba
