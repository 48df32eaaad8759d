#include "grid_neighbours.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <utility>

namespace pnpba {

// On a grid of radius-sized cells, a point's neighbours are in the 27 cells around its own.
// Points sorted by cell make the three cells of a row along x one contiguous run, so the points of
// one cell share nine runs of candidates, scanned as plain arrays (a k-d tree's radius search,
// Open3D's nanoflann, walks and sorts for every point).
GridNeighbours nearestWithin(const std::vector<Eigen::Vector3d>& points, double radius,
                             int max_neighbours, bool sorted) {
  const int n = static_cast<int>(points.size());
  if (n == 0) return {};
  Eigen::Vector3d low = points[0];
  for (const Eigen::Vector3d& p : points) low = low.cwiseMin(p);
  auto cellOf = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d c = ((p - low) / radius).array().floor();
    return Eigen::Vector3i(static_cast<int>(c.x()), static_cast<int>(c.y()),
                           static_cast<int>(c.z()));
  };
  Eigen::Vector3i size(1, 1, 1);
  for (const Eigen::Vector3d& p : points) size = size.cwiseMax(cellOf(p) + Eigen::Vector3i::Ones());
  auto key = [&size](const Eigen::Vector3i& c) {
    return (static_cast<int64_t>(c.z()) * size.y() + c.y()) * size.x() + c.x();
  };
  std::vector<std::pair<int64_t, int>> by_cell(n);
  for (int i = 0; i < n; ++i) by_cell[i] = {key(cellOf(points[i])), i};
  std::sort(by_cell.begin(), by_cell.end());
  // The points in cell order, one array per coordinate.
  std::vector<double> xs(n), ys(n), zs(n);
  std::vector<int64_t> keys(n);
  for (int s = 0; s < n; ++s) {
    const Eigen::Vector3d& p = points[by_cell[s].second];
    xs[s] = p.x(), ys[s] = p.y(), zs[s] = p.z();
    keys[s] = by_cell[s].first;
  }
  auto firstAtOrAfter = [&keys](int64_t k) {
    return static_cast<int>(std::lower_bound(keys.begin(), keys.end(), k) - keys.begin());
  };

  GridNeighbours result;
  result.begin.resize(n);
  result.count.resize(n);
  result.cutoff2.assign(n, std::numeric_limits<double>::infinity());
  result.index.reserve(static_cast<size_t>(n) * std::min(max_neighbours, 64));
  result.distance2.reserve(result.index.capacity());
  const double r2 = radius * radius;
  std::vector<std::pair<int, int>> runs;
  std::vector<double> d2;
  std::vector<std::pair<double, int>> found;
  for (int cell_begin = 0; cell_begin < n;) {
    int cell_end = cell_begin;
    while (cell_end < n && keys[cell_end] == keys[cell_begin]) ++cell_end;
    // The nine runs: a run may take in a cell at the far end of the row before or after (x wraps
    // in the key), whose points the distance test then drops.
    const Eigen::Vector3i c = cellOf(points[by_cell[cell_begin].second]);
    runs.clear();
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        const Eigen::Vector3i m = c + Eigen::Vector3i(0, dy, dz);
        if (m.y() < 0 || m.z() < 0 || m.y() >= size.y() || m.z() >= size.z()) continue;
        const int64_t k = key(m);
        const int from = firstAtOrAfter(k - 1), to = firstAtOrAfter(k + 2);
        if (from < to) runs.emplace_back(from, to);
      }
    }
    for (int s = cell_begin; s < cell_end; ++s) {
      found.clear();
      const double x = xs[s], y = ys[s], z = zs[s];
      for (const auto& [from, to] : runs) {
        d2.resize(to - from);
        for (int t = from; t < to; ++t) {
          const double dx = xs[t] - x, dy = ys[t] - y, dz = zs[t] - z;
          d2[t - from] = dx * dx + dy * dy + dz * dz;
        }
        for (int t = from; t < to; ++t) {
          if (d2[t - from] < r2) found.emplace_back(d2[t - from], by_cell[t].second);
        }
      }
      const size_t keep = std::min(found.size(), static_cast<size_t>(max_neighbours));
      const int i = by_cell[s].second;
      if (keep < found.size()) {
        std::nth_element(found.begin(), found.begin() + keep - 1, found.end());
        result.cutoff2[i] = found[keep - 1].first;
      }
      if (sorted) std::sort(found.begin(), found.begin() + keep);
      result.begin[i] = static_cast<int>(result.index.size());
      result.count[i] = static_cast<int>(keep);
      for (size_t j = 0; j < keep; ++j) {
        result.distance2.push_back(found[j].first);
        result.index.push_back(found[j].second);
      }
    }
    cell_begin = cell_end;
  }
  return result;
}

}  // namespace pnpba
