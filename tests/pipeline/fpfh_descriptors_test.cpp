// The depth registration's descriptors and matches (pipeline/src/registration/registration.cpp)
// come from pnpba's own FPFH (fpfh.h) and a single-precision scan (nearest_descriptors.h) on
// the grounds that they equal Open3D's ComputeFPFHFeature (tensor and legacy, which agree) and
// KDTreeFlann's exact double search. This checks that ground on rendered rooms, so an Open3D that
// computes them differently shows here.
#include <gtest/gtest.h>
#include <oneapi/tbb/global_control.h>
#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/pipelines/registration/Feature.h>
#include <open3d/t/geometry/PointCloud.h>
#include <open3d/t/pipelines/registration/Feature.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <tuple>

#include "depth_cloud.h"
#include "fpfh.h"
#include "grid_neighbours.h"
#include "grid_scan.h"
#include "pair_bins.h"
#include "pnpba/core/cpu_features.h"
#include "pnpba/pipeline/nearest_descriptors.h"
#include "pnpba/synthetic/synthetic_pair.h"
#include "point_normals.h"
#include "wide_baseline_pairs.h"

namespace pnpba {
namespace {

namespace reg = open3d::pipelines::registration;
using open3d::core::Tensor;

// pnpba's cloud of Open3D's (points and normals).
Cloud ours(const open3d::geometry::PointCloud& cloud) {
  Cloud c;
  c.points = cloud.points_;
  c.normals = cloud.normals_;
  return c;
}

// The sweep's poor room turned 45 degrees (a cell the depths must carry), at the registration's
// 10 cm voxel, down-sampled with normals by Open3D.
std::shared_ptr<open3d::geometry::PointCloud> roomCloud(
    int seed, double voxel, bench::SweepScene scene = bench::SweepScene::kPoor) {
  const SyntheticPairOptions o = bench::wideBaselinePair(scene, 45.0, 0.5, seed);
  const SyntheticPair p = renderSyntheticPair(o);
  auto cloud =
      open3d::geometry::PointCloud(
          depthCloud(p.view1.depth, o.camera.pinhole, o.camera.depth_scale, 4, 6.0)->points)
          .VoxelDownSample(voxel);
  cloud->EstimateNormals(open3d::geometry::KDTreeSearchParamHybrid(2.0 * voxel, 30));
  cloud->OrientNormalsTowardsCameraLocation(Eigen::Vector3d::Zero());
  return cloud;
}

Eigen::MatrixXd tensorFpfh(const open3d::geometry::PointCloud& cloud, double voxel) {
  const auto t = open3d::t::geometry::PointCloud::FromLegacy(cloud, open3d::core::Float64);
  const Tensor rows =
      open3d::t::pipelines::registration::ComputeFPFHFeature(t, 100, 5.0 * voxel).Contiguous();
  return Eigen::Map<const Eigen::MatrixXd>(rows.GetDataPtr<double>(), 33, rows.GetShape(0));
}

TEST(FpfhDescriptors, TheTensorPipelinesEqualTheLegacyOnes) {
  constexpr double kVoxel = 0.1;
  const auto cloud = roomCloud(0, kVoxel);
  ASSERT_GT(cloud->points_.size(), 1000u);
  const auto legacy =
      reg::ComputeFPFHFeature(*cloud, open3d::geometry::KDTreeSearchParamHybrid(5.0 * kVoxel, 100));
  const Eigen::MatrixXd tensor = tensorFpfh(*cloud, kVoxel);
  ASSERT_EQ(tensor.cols(), legacy->data_.cols());
  // A point's own histogram and its neighbours' weighted one each sum to 100 per group of 11
  // bins: 600 in all (a check that the comparison below compares descriptors).
  EXPECT_NEAR(legacy->data_.col(0).sum(), 600.0, 1e-6);
  EXPECT_LE((tensor - legacy->data_).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(FpfhDescriptors, ThePluginsDescriptorsEqualOpen3ds) {
  constexpr double kVoxel = 0.1;
  for (int seed : {0, 1}) {
    const auto cloud = roomCloud(seed, kVoxel);
    const Eigen::MatrixXd open3d = tensorFpfh(*cloud, kVoxel);
    const Eigen::MatrixXd mine = fpfhDescriptors(ours(*cloud), 100, 5.0 * kVoxel);
    ASSERT_EQ(mine.cols(), open3d.cols());
    EXPECT_NEAR(mine.col(0).sum(), 600.0, 1e-6);
    EXPECT_LE((mine - open3d).cwiseAbs().maxCoeff(), 1e-9) << "seed " << seed;
  }
  // The cabinet scene at its 6.5 cm voxel, a denser cloud whose points mostly have more than 100
  // within the radius. Its flat fronts on a regular grid put neighbours at equal distances, and
  // which of them a point keeps at its 100th is Open3D's k-d tree's choice there, the lower point
  // number here; moved by a micrometre at random, no two distances tie.
  {
    constexpr double kCabinetVoxel = 0.065;
    const auto cloud = roomCloud(0, kCabinetVoxel, bench::SweepScene::kCabinet);
    std::mt19937 random(7);
    std::uniform_real_distribution<double> jitter(-1e-6, 1e-6);
    for (Eigen::Vector3d& p : cloud->points_)
      p += Eigen::Vector3d(jitter(random), jitter(random), jitter(random));
    const Eigen::MatrixXd open3d = tensorFpfh(*cloud, kCabinetVoxel);
    const Eigen::MatrixXd mine = fpfhDescriptors(ours(*cloud), 100, 5.0 * kCabinetVoxel);
    ASSERT_EQ(mine.cols(), open3d.cols());
    EXPECT_LE((mine - open3d).cwiseAbs().maxCoeff(), 1e-9) << "cabinet";
  }
  // A cloud of one point, and points without neighbours, give empty histograms as Open3D's do.
  Cloud lonely;
  lonely.points = {{0, 0, 1}, {5, 0, 1}};
  lonely.normals = {{0, 0, -1}, {0, 0, -1}};
  EXPECT_EQ(fpfhDescriptors(lonely, 100, 0.5).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_THROW(fpfhDescriptors(lonely, 100, 0.0), std::invalid_argument);
  EXPECT_THROW(fpfhDescriptors(lonely, 0, 0.5), std::invalid_argument);
  lonely.normals.clear();
  EXPECT_THROW(fpfhDescriptors(lonely, 100, 0.5), std::invalid_argument);
}

// The registration's normals (point_normals.h) are Open3D's: the same neighbours, summed in the
// same order, and the same eigenvector to round-off; where a surface is seen edge-on the sign of
// a normal is a tie, which round-off may break the other way.
// The pair features and the neighbours' weighted histograms four at a time (AVX2) must leave
// every descriptor as one at a time makes it, to the last bit, in every room and in the cabinet
// scene.
TEST(FpfhDescriptors, FourWideKernelsChangeNoBit) {
  if (!cpuHasAvx2Fma()) GTEST_SKIP() << "no AVX2 on this CPU";
  for (const auto& [scene, voxel] :
       {std::pair{bench::SweepScene::kPoor, 0.1}, std::pair{bench::SweepScene::kRich, 0.1},
        std::pair{bench::SweepScene::kCabinet, 0.065}}) {
    for (int seed : {0, 1}) {
      const auto cloud = roomCloud(seed, voxel, scene);
      const Eigen::MatrixXd one = fpfhDescriptors(ours(*cloud), 100, 5.0 * voxel, false);
      const Eigen::MatrixXd four = fpfhDescriptors(ours(*cloud), 100, 5.0 * voxel, true);
      ASSERT_EQ(one.cols(), four.cols());
      EXPECT_EQ((one.array() != four.array()).count(), 0)
          << bench::toString(scene) << " seed " << seed;
    }
  }
}

// The weighted sums run in blocks on whichever core is free (the registration describes its two
// clouds side by side): the descriptors are the same bits on one thread as on two.
TEST(FpfhDescriptors, TheSameOnOneThreadAsOnTwo) {
  for (const auto& [scene, voxel] :
       {std::pair{bench::SweepScene::kPoor, 0.1}, std::pair{bench::SweepScene::kCabinet, 0.065}}) {
    const auto cloud = roomCloud(1, voxel, scene);
    auto describeOn = [&](int threads) {
      const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      return Eigen::MatrixXd(fpfhDescriptors(ours(*cloud), 100, 5.0 * voxel));
    };
    const Eigen::MatrixXd one = describeOn(1);
    const Eigen::MatrixXd two = describeOn(2);
    ASSERT_EQ(one.cols(), two.cols());
    ASSERT_GT(one.cols(), 1000) << "a cloud of many blocks";
    EXPECT_EQ((one.array() != two.array()).count(), 0) << bench::toString(scene);
  }
}

// The neighbour search runs in chunks of cells that either core takes: its lists, joined, are the
// same on one thread as on two, at the normals' and the descriptors' radii.
TEST(GridNeighbours, TheSameOnOneThreadAsOnTwo) {
  for (const auto& [scene, voxel] :
       {std::pair{bench::SweepScene::kPoor, 0.1}, std::pair{bench::SweepScene::kCabinet, 0.065}}) {
    const auto cloud = roomCloud(1, voxel, scene);
    ASSERT_GT(cloud->points_.size(), 1000u) << "a cloud of many chunks";
    for (const auto& [radius, max_neighbours, sorted] :
         {std::tuple{2.0 * voxel, 30, true}, std::tuple{5.0 * voxel, 100, false}}) {
      auto searchOn = [&, radius = radius, max_neighbours = max_neighbours,
                       sorted = sorted](int threads) {
        const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        return nearestWithin(cloud->points_, radius, max_neighbours, sorted);
      };
      const GridNeighbours one = searchOn(1), two = searchOn(2);
      EXPECT_EQ(one.begin, two.begin);
      EXPECT_EQ(one.count, two.count);
      EXPECT_EQ(one.index, two.index);
      EXPECT_EQ(one.distance2, two.distance2);
      EXPECT_EQ(one.cutoff2, two.cutoff2);
      // Every point's list is its own stretch, one after another in the joined arrays.
      size_t listed = 0;
      for (size_t i = 0; i < one.count.size(); ++i) listed += one.count[i];
      EXPECT_EQ(listed, one.index.size());
    }
  }
}

// A vector scan of the neighbour search finds every point's neighbours as the one-at-a-time scan
// does, in the same order and to the last bit of each distance, at the normals' and the
// descriptors' radii, sorted or not.
void expectTheScalarScansNeighbours(GridScan scan) {
  for (const auto& [scene, voxel] :
       {std::pair{bench::SweepScene::kPoor, 0.1}, std::pair{bench::SweepScene::kCabinet, 0.065}}) {
    const auto cloud = roomCloud(0, voxel, scene);
    for (const auto& [radius, max_neighbours, sorted] :
         {std::tuple{2.0 * voxel, 30, true}, std::tuple{5.0 * voxel, 100, false}}) {
      const GridNeighbours one =
          nearestWithin(cloud->points_, radius, max_neighbours, sorted, GridScan::kScalar);
      const GridNeighbours wide =
          nearestWithin(cloud->points_, radius, max_neighbours, sorted, scan);
      EXPECT_EQ(one.begin, wide.begin);
      EXPECT_EQ(one.count, wide.count);
      EXPECT_EQ(one.index, wide.index);
      EXPECT_EQ(one.distance2, wide.distance2);  // doubles compared exactly
      EXPECT_EQ(one.cutoff2, wide.cutoff2);
      EXPECT_GT(one.index.size(), 10 * cloud->points_.size()) << "a search with neighbours";
    }
  }
}

TEST(GridNeighbours, FourWideScanChangesNoBit) {
  if (!gridScanAvailable(GridScan::kAvx2)) GTEST_SKIP() << "no AVX2 on this CPU";
  expectTheScalarScansNeighbours(GridScan::kAvx2);
}

TEST(GridNeighbours, EightWideScanChangesNoBit) {
  if (!gridScanAvailable(GridScan::kAvx512)) GTEST_SKIP() << "no AVX-512 on this CPU";
  expectTheScalarScansNeighbours(GridScan::kAvx512);
}

// A run shorter than four, or ending part-way through a step, keeps exactly its candidates within
// the radius: a row of points at every distance around the radius, scanned from every start.
TEST(GridNeighbours, FourWideScanKeepsOnlyItsRunsCandidates) {
  if (!gridScanAvailable(GridScan::kAvx2)) GTEST_SKIP() << "no AVX2 on this CPU";
  const int n = 11;
  std::vector<double> xs(n), ys(n, 0.0), zs(n, 0.0);
  std::vector<int> ids(n);
  for (int i = 0; i < n; ++i) xs[i] = 0.1 * i, ids[i] = 100 + i;
  const double r2 = 0.55 * 0.55;  // points 0 .. 5 are within the radius of 0
  for (int from = 0; from < n; ++from) {
    for (int to = from; to <= n; ++to) {
      std::vector<double> d2(n + 3, -1.0);
      std::vector<int> id(n + 3, -1);
      const size_t kept = scanRunAvx2(xs.data(), ys.data(), zs.data(), ids.data(), from, to, 0.0,
                                      0.0, 0.0, r2, d2.data(), id.data(), 0);
      std::vector<int> expected;
      for (int t = from; t < to; ++t) {
        if (xs[t] * xs[t] < r2) expected.push_back(100 + t);
      }
      ASSERT_EQ(kept, expected.size()) << from << " .. " << to;
      for (size_t j = 0; j < kept; ++j) {
        EXPECT_EQ(id[j], expected[j]);
        EXPECT_EQ(d2[j], xs[id[j] - 100] * xs[id[j] - 100]);
      }
    }
  }
}

// Point i's neighbours by brute force: every point within the radius (squared distance computed
// as the search computes it), the max_neighbours nearest by (distance, point number).
std::vector<std::pair<double, int>> nearestByBruteForce(const std::vector<Eigen::Vector3d>& points,
                                                        int i, double radius, int max_neighbours,
                                                        double* cutoff2) {
  std::vector<std::pair<double, int>> within;
  for (int j = 0; j < static_cast<int>(points.size()); ++j) {
    const double dx = points[j].x() - points[i].x(), dy = points[j].y() - points[i].y(),
                 dz = points[j].z() - points[i].z();
    const double d = dx * dx + dy * dy + dz * dz;
    if (d < radius * radius) within.emplace_back(d, j);
  }
  std::sort(within.begin(), within.end());
  *cutoff2 = std::numeric_limits<double>::infinity();
  if (within.size() > static_cast<size_t>(max_neighbours)) {
    within.resize(max_neighbours);
    *cutoff2 = within.back().first;
  }
  return within;
}

// A lattice of 2 cm steps, whose points tie in distance by the dozen (so the 100th is chosen
// among ties), and a rendered room's cloud.
std::vector<std::vector<Eigen::Vector3d>> neighbourTestClouds() {
  std::vector<Eigen::Vector3d> lattice;
  for (int x = 0; x < 14; ++x)
    for (int y = 0; y < 14; ++y)
      for (int z = 0; z < 3; ++z) lattice.emplace_back(0.02 * x, 0.02 * y, 1.0 + 0.02 * z);
  return {lattice, roomCloud(0, 0.1)->points_};
}

TEST(GridNeighbours, KeepTheNearestWithinTheRadiusTiesByPointNumber) {
  for (const std::vector<Eigen::Vector3d>& points : neighbourTestClouds()) {
    const double scale = points.size() < 1000 ? 0.02 : 0.1;
    int cut = 0;
    for (const auto& [radius, max_neighbours, sorted] :
         {std::tuple{5.0 * scale, 100, false}, std::tuple{2.0 * scale, 30, true},
          std::tuple{3.0 * scale, 7, false}}) {
      const GridNeighbours nb = nearestWithin(points, radius, max_neighbours, sorted);
      for (int i = 0; i < static_cast<int>(points.size()); ++i) {
        double cutoff2 = 0;
        const auto expected = nearestByBruteForce(points, i, radius, max_neighbours, &cutoff2);
        std::vector<std::pair<double, int>> found;
        for (int j = nb.begin[i]; j < nb.begin[i] + nb.count[i]; ++j) {
          found.emplace_back(nb.distance2[j], nb.index[j]);
        }
        if (!sorted) std::sort(found.begin(), found.end());
        ASSERT_EQ(found, expected) << "point " << i << " radius " << radius;
        ASSERT_EQ(nb.cutoff2[i], cutoff2) << "point " << i;
        cut += std::isfinite(cutoff2);
      }
    }
    EXPECT_GT(cut, 100) << "searches where lists are cut";
  }
}

TEST(PointNormals, EqualOpen3dsEstimateNormals) {
  constexpr double kNormalTolerance = 1e-6;
  for (auto [scene, voxel] :
       {std::pair{bench::SweepScene::kPoor, 0.1}, std::pair{bench::SweepScene::kCabinet, 0.065}}) {
    const auto open3d = roomCloud(1, voxel, scene);
    Cloud mine;
    mine.points = open3d->points_;
    estimateNormals(&mine, 2.0 * voxel, 30);
    orientNormalsTowardsCamera(&mine);
    ASSERT_EQ(mine.normals.size(), open3d->normals_.size());
    double worst = 0;
    int flipped = 0;
    for (size_t i = 0; i < mine.normals.size(); ++i) {
      EXPECT_NEAR(mine.normals[i].norm(), 1.0, 1e-12) << "point " << i;
      double apart = (mine.normals[i] - open3d->normals_[i]).norm();
      if (apart > 1.0) {
        // Turned the other way: only where the surface is seen edge-on, the sign a tie.
        ++flipped;
        const double facing = std::abs(open3d->normals_[i].dot(open3d->points_[i].normalized()));
        EXPECT_LE(facing, 1e-6) << "point " << i << " flipped";
        apart = (mine.normals[i] + open3d->normals_[i]).norm();
      }
      worst = std::max(worst, apart);
    }
    // Measured: 1 of 5573 points flipped (seen edge-on to 1e-8) on the poor room, none of 7704
    // on the cabinet; the rest within 4e-8.
    EXPECT_LE(flipped * 1000, static_cast<int>(mine.normals.size())) << "voxel " << voxel;
    // Open3D's eigenvector and Eigen's closed-form one agree to round-off, up to the sign where
    // the surface is seen edge-on.
    EXPECT_LE(worst, kNormalTolerance) << "voxel " << voxel;
  }
  // Too few neighbours: the optical axis, turned to face the camera.
  Cloud pair;
  pair.points = {{0, 0, 1}, {0.01, 0, 1}};
  estimateNormals(&pair, 0.1, 30);
  ASSERT_EQ(pair.normals.size(), 2u);
  EXPECT_EQ(pair.normals[0], Eigen::Vector3d(0, 0, 1));
  orientNormalsTowardsCamera(&pair);
  EXPECT_EQ(pair.normals[0], Eigen::Vector3d(0, 0, -1));
}

TEST(FpfhDescriptors, SinglePrecisionMatchingFindsTheLegacyNearestNeighbours) {
  constexpr double kVoxel = 0.1;
  const Eigen::MatrixXd a = tensorFpfh(*roomCloud(0, kVoxel), kVoxel);
  const Eigen::MatrixXd b = tensorFpfh(*roomCloud(1, kVoxel), kVoxel);
  // 33 x n column-major: the floats of one descriptor after another, as the registration passes
  // them.
  const Eigen::MatrixXf a_rows = a.cast<float>(), b_rows = b.cast<float>();
  const NearestBothWays nearest = nearestBothWays(a_rows.data(), static_cast<int>(a.cols()),
                                                  b_rows.data(), static_cast<int>(b.cols()), 33);

  reg::Feature legacy_b;
  legacy_b.data_ = b;
  const open3d::geometry::KDTreeFlann tree(legacy_b);
  std::vector<int> index(1);
  std::vector<double> distance2(1);
  int same = 0;
  for (int i = 0; i < a.cols(); ++i) {
    tree.SearchKNN(Eigen::VectorXd(a.col(i)), 1, index, distance2);
    same += index[0] == nearest.a_to_b[i];
  }
  // Ties and float rounding may flip a rare match; measured: none on the rendered rooms.
  EXPECT_GE(same, static_cast<int>(0.999 * a.cols()));
}

}  // namespace
}  // namespace pnpba
