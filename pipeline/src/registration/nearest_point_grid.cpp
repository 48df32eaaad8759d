#include "nearest_point_grid.h"

#include <algorithm>
#include <cmath>

namespace pnpba {

namespace {

// About this many cells at most: a cloud spread wider (a stray far point) gets coarser cells,
// which stay exact (27 of them still cover the distance) and only read more points.
constexpr double kMaxCells = 1 << 20;

}  // namespace

NearestPointGrid::NearestPointGrid(const std::vector<Eigen::Vector3d>& points, double distance)
    : points_(points), distance_(distance), distance2_(distance * distance) {
  if (points.empty() || !(distance > 0)) return;
  low_ = points[0];
  Eigen::Vector3d high = points[0];
  for (const Eigen::Vector3d& p : points) low_ = low_.cwiseMin(p), high = high.cwiseMax(p);
  const Eigen::Vector3d extent = (high - low_).cwiseMax(distance);
  distance_ = std::max(distance, std::cbrt(extent.prod() / kMaxCells));
  for (int a = 0; a < 3; ++a) {
    size_[a] = static_cast<int>(std::floor((high[a] - low_[a]) / distance_)) + 1;
  }
  const size_t cells = static_cast<size_t>(size_.x()) * size_.y() * size_.z();
  std::vector<int> cell(points.size());
  start_.assign(cells + 1, 0);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d c = ((points[i] - low_) / distance_).array().floor();
    cell[i] = (static_cast<int>(c.z()) * size_.y() + static_cast<int>(c.y())) * size_.x() +
              static_cast<int>(c.x());
    ++start_[cell[i] + 1];
  }
  for (size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
  std::vector<int> fill(start_.begin(), start_.end() - 1);
  order_.resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) order_[fill[cell[i]]++] = static_cast<int>(i);
}

bool NearestPointGrid::nearest(const Eigen::Vector3d& q, double* distance2) const {
  if (order_.empty()) return false;
  const Eigen::Vector3d c = ((q - low_) / distance_).array().floor();
  int from[3], to[3];
  for (int a = 0; a < 3; ++a) {
    // Far outside the grid: no cell within reach (and no overflow converting to int).
    if (!(c[a] >= -1 && c[a] <= size_[a])) return false;
    from[a] = std::max(static_cast<int>(c[a]) - 1, 0);
    to[a] = std::min(static_cast<int>(c[a]) + 1, size_[a] - 1);
  }
  double best = distance2_;
  bool found = false;
  for (int z = from[2]; z <= to[2]; ++z) {
    for (int y = from[1]; y <= to[1]; ++y) {
      const int row = (z * size_.y() + y) * size_.x();
      for (int k = start_[row + from[0]]; k < start_[row + to[0] + 1]; ++k) {
        const Eigen::Vector3d& p = points_[order_[k]];
        const double dx = q.x() - p.x(), dy = q.y() - p.y(), dz = q.z() - p.z();
        const double d2 = dx * dx + dy * dy + dz * dz;
        if (d2 < best) best = d2, found = true;
      }
    }
  }
  if (found) *distance2 = best;
  return found;
}

}  // namespace pnpba
