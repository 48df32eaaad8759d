// The registration sizes its voxel by occupiedVoxels (voxel_count.h) instead of down-sampling
// cloud 1 to count it: the count must be Open3D's VoxelDownSample's size, on the clouds the
// registration sees and on the grid's boundaries, where a rounding apart would move a point.
#include "voxel_count.h"

#include <gtest/gtest.h>
#include <open3d/geometry/PointCloud.h>

#include <random>

#include "depth_cloud.h"
#include "pnpba/synthetic/synthetic_pair.h"
#include "wide_baseline_pairs.h"

namespace pnpba {
namespace {

size_t open3dCount(const std::vector<Eigen::Vector3d>& points, double voxel) {
  open3d::geometry::PointCloud cloud(points);
  return cloud.VoxelDownSample(voxel)->points_.size();
}

TEST(VoxelCount, EqualsOpen3dsDownSampleOnRenderedRooms) {
  for (const bench::SweepScene scene : {bench::SweepScene::kPoor, bench::SweepScene::kCabinet}) {
    const SyntheticPairOptions o = bench::wideBaselinePair(scene, 30.0, 0.5, 1);
    const SyntheticPair p = renderSyntheticPair(o);
    const auto cloud = depthCloud(p.view1.depth, o.camera.pinhole, o.camera.depth_scale, 4, 6.0);
    ASSERT_GT(cloud->points_.size(), 5000u);
    for (const double voxel : {0.013, 0.05, 0.1, 0.1234567, 0.3, 2.0}) {
      EXPECT_EQ(occupiedVoxels(cloud->points_, voxel), open3dCount(cloud->points_, voxel))
          << "voxel " << voxel;
    }
  }
}

TEST(VoxelCount, EqualsOpen3dsDownSampleOnTheGridsBoundaries) {
  // Points on multiples of the voxel and one ulp either side, where floor decides the voxel.
  std::mt19937 random(7);
  std::uniform_int_distribution<int> cell(-40, 40);
  std::uniform_int_distribution<int> side(-1, 1);
  for (const double voxel : {0.1, 0.05, 0.07}) {
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < 3000; ++i) {
      Eigen::Vector3d p;
      for (int axis = 0; axis < 3; ++axis) {
        const double on = cell(random) * voxel;
        const int s = side(random);
        p(axis) = s == 0 ? on : std::nextafter(on, s * 1e9);
      }
      points.push_back(p);
    }
    EXPECT_EQ(occupiedVoxels(points, voxel), open3dCount(points, voxel)) << "voxel " << voxel;
  }
}

TEST(VoxelCount, CountsOnePointAndNoneAndAGridTooWideForItsKey) {
  EXPECT_EQ(occupiedVoxels({}, 0.1), 0u);
  EXPECT_EQ(occupiedVoxels({Eigen::Vector3d(1, 2, 3)}, 0.1), 1u);
  EXPECT_EQ(occupiedVoxels({Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(1, 2, 3)}, 0.1), 1u);
  // 1000 m across at 0.1 mm: ten million voxels a side, past the 21-bit key.
  std::vector<Eigen::Vector3d> wide = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1000, 0, 0),
                                       Eigen::Vector3d(1000, 0, 0.00002),
                                       Eigen::Vector3d(500, 1e-5, 3)};
  EXPECT_EQ(occupiedVoxels(wide, 1e-4), open3dCount(wide, 1e-4));
  EXPECT_EQ(occupiedVoxels(wide, 1e-4), 3u);
}

}  // namespace
}  // namespace pnpba
