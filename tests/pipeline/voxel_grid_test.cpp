// The registration down-samples its clouds by voxelDownSample (voxel_grid.h) and sizes its voxel
// by occupiedVoxels instead of down-sampling cloud 1 to count it: the points must be Open3D's
// VoxelDownSample's, in its order, and the count its size, on the clouds the
// registration sees and on the grid's boundaries, where a rounding apart would move a point.
#include "voxel_grid.h"

#include <gtest/gtest.h>
#include <open3d/geometry/PointCloud.h>

#include <algorithm>
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

TEST(VoxelDownSample, GivesOpen3dsPointsInOpen3dsOrder) {
  for (const bench::SweepScene scene : {bench::SweepScene::kPoor, bench::SweepScene::kCabinet}) {
    const SyntheticPairOptions o = bench::wideBaselinePair(scene, 30.0, 0.5, 1);
    const SyntheticPair p = renderSyntheticPair(o);
    Cloud cloud = *depthCloud(p.view1.depth, o.camera.pinhole, o.camera.depth_scale, 4, 6.0);
    ASSERT_GT(cloud.points.size(), 5000u);
    // Normals to average too: any unit vectors, one per point.
    for (const Eigen::Vector3d& q : cloud.points) cloud.normals.push_back(q.normalized());
    for (const double voxel : {0.013, 0.065, 0.1, 0.3}) {
      const Cloud mine = voxelDownSample(cloud, voxel);
      open3d::geometry::PointCloud theirs(cloud.points);
      theirs.normals_ = cloud.normals;
      const auto open3d = theirs.VoxelDownSample(voxel);
      // The same points in the same order, to the bit.
      EXPECT_EQ(mine.points, open3d->points_) << "voxel " << voxel;
      EXPECT_EQ(mine.normals, open3d->normals_) << "voxel " << voxel;
      EXPECT_EQ(mine.points.size(), occupiedVoxels(cloud.points, voxel));
    }
  }
  EXPECT_TRUE(voxelDownSample(Cloud{}, 0.1).points.empty());
}

TEST(VoxelCount, EqualsOpen3dsDownSampleOnRenderedRooms) {
  for (const bench::SweepScene scene : {bench::SweepScene::kPoor, bench::SweepScene::kCabinet}) {
    const SyntheticPairOptions o = bench::wideBaselinePair(scene, 30.0, 0.5, 1);
    const SyntheticPair p = renderSyntheticPair(o);
    const auto cloud = depthCloud(p.view1.depth, o.camera.pinhole, o.camera.depth_scale, 4, 6.0);
    ASSERT_GT(cloud->points.size(), 5000u);
    for (const double voxel : {0.013, 0.05, 0.1, 0.1234567, 0.3, 2.0}) {
      EXPECT_EQ(occupiedVoxels(cloud->points, voxel), open3dCount(cloud->points, voxel))
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
  Cloud wide_cloud;
  wide_cloud.points = wide;
  EXPECT_EQ(voxelDownSample(wide_cloud, 1e-4).points.size(), 3u);
}

}  // namespace
}  // namespace pnpba
