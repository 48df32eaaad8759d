// The registration candidates' overlap (registration/registration.cpp) finds each moved point's
// nearest target point on a grid (nearest_point_grid.h) instead of Open3D's k-d tree: the same
// nearest distance, whether the query lies inside the cloud, at its edge or far outside, and on a
// cloud spread wide enough that the grid coarsens its cells.
#include "nearest_point_grid.h"

#include <gtest/gtest.h>
#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/geometry/PointCloud.h>

#include <limits>
#include <random>
#include <vector>

namespace pnpba {
namespace {

// The nearest point closer than `distance` by looking at every point: the independent answer.
bool bruteForce(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& q,
                double distance, double* distance2) {
  double best = distance * distance;
  bool found = false;
  for (const Eigen::Vector3d& p : points) {
    const double d2 = (q - p).squaredNorm();
    if (d2 < best) best = d2, found = true;
  }
  if (found) *distance2 = best;
  return found;
}

void expectSameAsBruteForceAndKdTree(const std::vector<Eigen::Vector3d>& cloud,
                                     const std::vector<Eigen::Vector3d>& queries, double distance) {
  const NearestPointGrid grid(cloud, distance);
  open3d::geometry::PointCloud target;
  target.points_ = cloud;
  const open3d::geometry::KDTreeFlann tree(target);
  int hits = 0;
  for (const Eigen::Vector3d& q : queries) {
    double g = -1, b = -1;
    const bool in_grid = grid.nearest(q, &g);
    ASSERT_EQ(in_grid, bruteForce(cloud, q, distance, &b)) << q.transpose();
    std::vector<int> index(1);
    std::vector<double> d2(1);
    const bool in_tree = tree.SearchHybrid(q, distance, 1, index, d2) > 0;
    ASSERT_EQ(in_grid, in_tree) << q.transpose();
    if (!in_grid) continue;
    ++hits;
    EXPECT_NEAR(g, b, 1e-15);
    EXPECT_NEAR(g, d2[0], 1e-15);
  }
  EXPECT_GT(hits, static_cast<int>(queries.size()) / 10);  // the test reaches the cloud
}

TEST(NearestPointGrid, FindsTheNearestPointWithinTheDistanceAsAKdTreeDoes) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> room(-4.0, 4.0);
  // Points on three walls of a room (as a down-sampled depth cloud lies on surfaces).
  std::vector<Eigen::Vector3d> cloud;
  for (int i = 0; i < 3000; ++i) {
    Eigen::Vector3d p(room(rng), room(rng), room(rng));
    p[i % 3] = 4.0;
    cloud.push_back(p);
  }
  // Queries near the cloud (moved points of a registration candidate, up to the distance
  // off), inside the room, and far outside every cell.
  auto queriesFor = [&](double distance) {
    std::uniform_real_distribution<double> jitter(-distance, distance);
    std::vector<Eigen::Vector3d> queries;
    for (const Eigen::Vector3d& p : cloud) {
      queries.push_back(p + Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng)));
    }
    for (int i = 0; i < 300; ++i) queries.emplace_back(room(rng), room(rng), room(rng));
    queries.emplace_back(1e6, 0, 0);
    queries.emplace_back(-1e300, 1e300, 0);
    queries.emplace_back(std::numeric_limits<double>::quiet_NaN(), 0, 0);
    return queries;
  };
  for (double distance : {0.05, 0.15, 0.6}) {
    expectSameAsBruteForceAndKdTree(cloud, queriesFor(distance), distance);
  }

  // One point 500 m away: the grid coarsens its cells (at most about a million) and stays exact.
  cloud.emplace_back(500.0, 0.0, 0.0);
  std::vector<Eigen::Vector3d> queries = queriesFor(0.15);
  queries.emplace_back(500.1, 0.0, 0.0);
  expectSameAsBruteForceAndKdTree(cloud, queries, 0.15);
}

TEST(NearestPointGrid, AnEmptyCloudHasNoNearestPoint) {
  const std::vector<Eigen::Vector3d> none;
  const NearestPointGrid grid(none, 0.1);
  double d2 = -1;
  EXPECT_FALSE(grid.nearest(Eigen::Vector3d::Zero(), &d2));
  EXPECT_EQ(d2, -1);
}

}  // namespace
}  // namespace pnpba
