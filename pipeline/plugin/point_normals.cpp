#include "point_normals.h"

#include <open3d/geometry/KDTreeSearchParam.h>

#include <vector>

#include "grid_neighbours.h"

namespace pnpba {

void estimateNormals(open3d::geometry::PointCloud* cloud, double radius, int max_neighbours) {
  const std::vector<Eigen::Vector3d>& points = cloud->points_;
  const GridNeighbours nb = nearestWithin(points, radius, max_neighbours, /*sorted=*/true);
  std::vector<Eigen::Matrix3d> covariances(points.size(), Eigen::Matrix3d::Identity());
  for (size_t i = 0; i < points.size(); ++i) {
    const int begin = nb.begin[i], k = nb.count[i];
    if (k < 3) continue;
    // Means of x, y, z and of their products, then covariance = E[ab] - E[a] E[b].
    Eigen::Matrix<double, 9, 1> moments = Eigen::Matrix<double, 9, 1>::Zero();
    for (int j = begin; j < begin + k; ++j) {
      const Eigen::Vector3d& p = points[nb.index[j]];
      moments(0) += p(0);
      moments(1) += p(1);
      moments(2) += p(2);
      moments(3) += p(0) * p(0);
      moments(4) += p(0) * p(1);
      moments(5) += p(0) * p(2);
      moments(6) += p(1) * p(1);
      moments(7) += p(1) * p(2);
      moments(8) += p(2) * p(2);
    }
    moments /= static_cast<double>(k);
    Eigen::Matrix3d& c = covariances[i];
    c(0, 0) = moments(3) - moments(0) * moments(0);
    c(1, 1) = moments(6) - moments(1) * moments(1);
    c(2, 2) = moments(8) - moments(2) * moments(2);
    c(0, 1) = c(1, 0) = moments(4) - moments(0) * moments(1);
    c(0, 2) = c(2, 0) = moments(5) - moments(0) * moments(2);
    c(1, 2) = c(2, 1) = moments(7) - moments(1) * moments(2);
  }
  // Given covariances, Open3D's EstimateNormals searches nothing and only takes each one's
  // eigenvector of least eigenvalue.
  cloud->normals_.clear();
  cloud->covariances_ = std::move(covariances);
  cloud->EstimateNormals(open3d::geometry::KDTreeSearchParamHybrid(radius, max_neighbours));
  cloud->covariances_.clear();
}

}  // namespace pnpba
