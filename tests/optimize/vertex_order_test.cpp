// The optimizer keeps its vertices in id order whatever order they are added in: lookups find
// each one, and the solve (which orders the system by id) gives the same estimates to the bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "pnpba/core/error.h"
#include "pnpba/optimize/edge_se3_project_xyz.h"
#include "pnpba/optimize/sparse_optimizer.h"

namespace pnpba {
namespace {

constexpr int kPoints = 40;

// Two cameras (the first fixed) and kPoints points a little off where the cameras saw them;
// vertices are added in `order` (ids: 0, 1 cameras, 2.. points).
std::vector<SE3Quat> solve(const std::vector<int>& order, std::vector<Eigen::Vector3d>* points) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<> unit(-1.0, 1.0);
  Vector6d xi;
  xi << 0.02, -0.03, 0.01, 0.3, 0.05, 0.02;
  const SE3Quat T2 = SE3Quat::exp(xi);
  std::vector<Eigen::Vector3d> truth;
  for (int i = 0; i < kPoints; ++i) truth.emplace_back(unit(rng), unit(rng), 4 + unit(rng));

  SparseOptimizer opt;
  opt.setSolverBackend(SolverBackend::kNative);
  for (int id : order) {
    Vertex* v = nullptr;
    if (id < 2) {
      auto* pose = new VertexSE3Expmap();
      pose->setEstimate(id == 0 ? SE3Quat() : SE3Quat::exp(Vector6d::Constant(0.01)) * T2);
      pose->setFixed(id == 0);
      v = pose;
    } else {
      auto* point = new VertexPointXYZ();
      point->setEstimate(truth[id - 2] + Eigen::Vector3d(0.02, -0.01, 0.03));
      point->setMarginalized(true);
      v = point;
    }
    v->setId(id);
    opt.addVertex(v);
  }
  int edge_id = 0;
  for (int i = 0; i < kPoints; ++i) {
    for (int camera = 0; camera < 2; ++camera) {
      auto* e = new EdgeSE3ProjectXYZ();
      e->setId(edge_id++);
      e->setVertex(0, opt.vertex(2 + i));
      e->setVertex(1, opt.vertex(camera));
      const SE3Quat T = camera == 0 ? SE3Quat() : T2;
      e->fx = e->fy = 500, e->cx = 320, e->cy = 240;
      e->setMeasurement(e->intrinsics().project(T.map(truth[i])));
      opt.addEdge(e);
    }
  }
  opt.initializeOptimization();
  opt.optimize(20);
  std::vector<SE3Quat> poses;
  for (int id : {0, 1}) poses.push_back(static_cast<VertexSE3Expmap*>(opt.vertex(id))->estimate());
  points->clear();
  for (int i = 0; i < kPoints; ++i) {
    points->push_back(static_cast<VertexPointXYZ*>(opt.vertex(2 + i))->estimate());
  }
  return poses;
}

TEST(VertexOrder, AnyInsertionOrderGivesTheSameSolve) {
  std::vector<int> ascending(kPoints + 2);
  for (int i = 0; i < kPoints + 2; ++i) ascending[i] = i;
  std::vector<int> descending(ascending.rbegin(), ascending.rend());
  std::vector<int> shuffled = ascending;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(11));

  std::vector<Eigen::Vector3d> points_a, points_b;
  const std::vector<SE3Quat> a = solve(ascending, &points_a);
  // The solve moved the pose: the comparison below is of a real solution.
  EXPECT_GT((a[1].log() - SE3Quat::exp(Vector6d::Constant(0.01)).log()).norm(), 1e-3);
  for (const std::vector<int>& order : {descending, shuffled}) {
    const std::vector<SE3Quat> b = solve(order, &points_b);
    EXPECT_EQ(a[1].to_homogeneous_matrix(), b[1].to_homogeneous_matrix());
    for (int i = 0; i < kPoints; ++i) EXPECT_EQ(points_a[i], points_b[i]) << "point " << i;
  }
}

TEST(VertexOrder, LookupFindsEveryIdAndOnlyThose) {
  SparseOptimizer opt;
  for (int id : {7, 3, 11, 5, 1}) {
    auto* v = new VertexPointXYZ();
    v->setId(id);
    opt.addVertex(v);
  }
  for (int id = 0; id <= 12; ++id) {
    const bool added = id == 1 || id == 3 || id == 5 || id == 7 || id == 11;
    ASSERT_EQ(opt.vertex(id) != nullptr, added) << "id " << id;
    if (added) {
      EXPECT_EQ(opt.vertex(id)->id(), id);
      EXPECT_EQ(opt.vertex(id)->graph(), &opt);
    }
  }
}

TEST(VertexOrder, AVertexAddedTwiceIsRejectedAndStaysOwnedOnce) {
  SparseOptimizer opt, other;
  auto* v = new VertexPointXYZ();
  v->setId(4);
  opt.addVertex(v);
  EXPECT_THROW(opt.addVertex(v), Error);
  EXPECT_THROW(other.addVertex(v), Error);
  EXPECT_EQ(opt.numVertices(), 1u);
  EXPECT_EQ(other.numVertices(), 0u);
  EXPECT_EQ(opt.vertex(4), v);
}  // one delete of v, by opt: a second owner would free it twice

}  // namespace
}  // namespace pnpba
