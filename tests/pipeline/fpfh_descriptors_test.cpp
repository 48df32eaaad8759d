// The depth registration's descriptors and matches (pipeline/plugin/open3d_registration.cpp)
// come from Open3D's tensor pipeline and nanoflann in single precision on the grounds that
// they equal the legacy ComputeFPFHFeature and KDTreeFlann's exact double search. This checks
// that ground on a rendered room, so an Open3D that computes them differently shows here.
#include <gtest/gtest.h>

#include <open3d/core/nns/NearestNeighborSearch.h>
#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/pipelines/registration/Feature.h>
#include <open3d/t/geometry/PointCloud.h>
#include <open3d/t/pipelines/registration/Feature.h>

#include "depth_cloud.h"
#include "pnpba/synthetic/synthetic_pair.h"

namespace pnpba {
namespace {

namespace reg = open3d::pipelines::registration;
using open3d::core::Tensor;

// The plain room of the depth-path tests at the registration's 10 cm voxel.
std::shared_ptr<open3d::geometry::PointCloud> roomCloud(unsigned seed, double voxel) {
  SyntheticPairOptions o;
  o.seed = seed;
  o.layout = SceneLayout::kClosedRoom;
  o.texture = SceneTexture::kPoor;
  o.noise.max_range = 8.0;
  o.T_21 = SyntheticScene::lookAtMotion(45.0, Eigen::Vector3d(0.1, 1.0, -0.2), 0.5);
  const SyntheticPair p = renderSyntheticPair(o);
  auto cloud = depthCloud(p.view1.depth, o.camera.pinhole, o.camera.depth_scale, 4, 6.0)
                   ->VoxelDownSample(voxel);
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
  const auto cloud = roomCloud(1066, kVoxel);
  ASSERT_GT(cloud->points_.size(), 1000u);
  const auto legacy = reg::ComputeFPFHFeature(
      *cloud, open3d::geometry::KDTreeSearchParamHybrid(5.0 * kVoxel, 100));
  const Eigen::MatrixXd tensor = tensorFpfh(*cloud, kVoxel);
  ASSERT_EQ(tensor.cols(), legacy->data_.cols());
  // A point's own histogram and its neighbours' weighted one each sum to 100 per group of 11
  // bins: 600 in all (a check that the comparison below compares descriptors).
  EXPECT_NEAR(legacy->data_.col(0).sum(), 600.0, 1e-6);
  EXPECT_LE((tensor - legacy->data_).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(FpfhDescriptors, SinglePrecisionNanoflannFindsTheLegacyNearestNeighbours) {
  constexpr double kVoxel = 0.1;
  const Eigen::MatrixXd a = tensorFpfh(*roomCloud(1066, kVoxel), kVoxel);
  const Eigen::MatrixXd b = tensorFpfh(*roomCloud(1067, kVoxel), kVoxel);
  const Eigen::MatrixXf b_rows = b.cast<float>();  // 33 x n column-major: one row per point
  Tensor dataset({static_cast<int64_t>(b.cols()), 33}, open3d::core::Float32);
  std::copy(b_rows.data(), b_rows.data() + b_rows.size(), dataset.GetDataPtr<float>());
  Tensor queries({static_cast<int64_t>(a.cols()), 33}, open3d::core::Float32);
  const Eigen::MatrixXf a_rows = a.cast<float>();
  std::copy(a_rows.data(), a_rows.data() + a_rows.size(), queries.GetDataPtr<float>());
  open3d::core::nns::NearestNeighborSearch search(dataset);
  ASSERT_TRUE(search.KnnIndex());
  const Tensor index = search.KnnSearch(queries, 1).first.To(open3d::core::Int32).Contiguous();

  reg::Feature legacy_b;
  legacy_b.data_ = b;
  const open3d::geometry::KDTreeFlann tree(legacy_b);
  std::vector<int> nearest(1);
  std::vector<double> distance2(1);
  int same = 0;
  for (int i = 0; i < a.cols(); ++i) {
    tree.SearchKNN(Eigen::VectorXd(a.col(i)), 1, nearest, distance2);
    same += nearest[0] == index.GetDataPtr<int32_t>()[i];
  }
  // Ties and float rounding may flip a rare match; measured: none on the rendered rooms.
  EXPECT_GE(same, static_cast<int>(0.999 * a.cols()));
}

}  // namespace
}  // namespace pnpba
