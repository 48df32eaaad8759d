// Private to the depth-only registration (registration.cpp): the nearest point of a fixed cloud
// within a fixed distance of a query, on a dense grid of distance-sized cells, for the registration
// candidates' overlap (registration.cpp). A voxel-down-sampled cloud holds a few points per
// cell, so a query reads 27 small cells where a k-d tree (Open3D's KDTreeFlann) descends for each:
// the same nearest distance, several times faster.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace pnpba {

class NearestPointGrid {
 public:
  // `points` must outlive the grid. distance > 0.
  NearestPointGrid(const std::vector<Eigen::Vector3d>& points, double distance);

  // The squared distance from q to the nearest point closer than the distance (squared
  // distance below distance^2, as FLANN's radius search takes it); false when there is none.
  bool nearest(const Eigen::Vector3d& q, double* distance2) const;

 private:
  const std::vector<Eigen::Vector3d>& points_;
  double distance_;   // the cells' side: the distance, or more for a widely spread cloud
  double distance2_;  // the distance's square
  Eigen::Vector3d low_;
  Eigen::Vector3i size_ = Eigen::Vector3i::Zero();
  std::vector<int> start_;  // cell c's points are order_[start_[c] .. start_[c + 1])
  std::vector<int> order_;
};

}  // namespace pnpba
