#include "point_normals.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "grid_neighbours.h"

namespace pnpba {

void estimateNormals(Cloud* cloud, double radius, int max_neighbours) {
  const std::vector<Eigen::Vector3d>& points = cloud->points;
  const GridNeighbours nb = nearestWithin(points, radius, max_neighbours, /*sorted=*/true);
  std::vector<Eigen::Vector3d>& normals = cloud->normals;
  normals.assign(points.size(), Eigen::Vector3d::UnitZ());
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
    Eigen::Matrix3d c;
    c(0, 0) = moments(3) - moments(0) * moments(0);
    c(1, 1) = moments(6) - moments(1) * moments(1);
    c(2, 2) = moments(8) - moments(2) * moments(2);
    c(0, 1) = c(1, 0) = moments(4) - moments(0) * moments(1);
    c(0, 2) = c(2, 0) = moments(5) - moments(0) * moments(2);
    c(1, 2) = c(2, 1) = moments(7) - moments(1) * moments(2);
    // The closed-form solver: a few hundred ns where the iterative one takes microseconds; its
    // eigenvalues come in increasing order.
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(c);
    const Eigen::Vector3d least = solver.eigenvectors().col(0);
    const double length = least.norm();
    if (length > 0 && std::isfinite(length)) normals[i] = least / length;
  }
}

void orientNormalsTowardsCamera(Cloud* cloud) {
  for (size_t i = 0; i < cloud->points.size(); ++i) {
    Eigen::Vector3d& n = cloud->normals[i];
    const Eigen::Vector3d towards_camera = -cloud->points[i];
    if (n.norm() == 0.0) {
      const double length = towards_camera.norm();
      n = length == 0.0 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d(towards_camera / length);
    } else if (n.dot(towards_camera) < 0.0) {
      n = -n;
    }
  }
}

}  // namespace pnpba
