#include "grid_neighbours.h"

#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <utility>

#include "grid_scan.h"

namespace pnpba {

bool gridScanAvailable(GridScan scan) {
  static const bool has_avx2 = __builtin_cpu_supports("avx2");
  static const bool has_avx512 =
      __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl");
  if (scan == GridScan::kAvx2) return has_avx2;
  if (scan == GridScan::kAvx512) return has_avx512;
  return true;  // the scalar scan, or the widest there is
}

namespace {

GridScan widestScan() {
  if (gridScanAvailable(GridScan::kAvx512)) return GridScan::kAvx512;
  if (gridScanAvailable(GridScan::kAvx2)) return GridScan::kAvx2;
  return GridScan::kScalar;
}

}  // namespace

// On a grid of radius-sized cells, a point's neighbours are in the 27 cells around its own.
// Points sorted by cell make the three cells of a row along x one contiguous run, so the points of
// one cell share nine runs of candidates, scanned as plain arrays (a k-d tree's radius search,
// Open3D's nanoflann, walks and sorts for every point).
GridNeighbours nearestWithin(const std::vector<Eigen::Vector3d>& points, double radius,
                             int max_neighbours, bool sorted, GridScan scan) {
  if (scan == GridScan::kBest) scan = widestScan();
  if (!gridScanAvailable(scan)) scan = GridScan::kScalar;
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
  std::vector<int> ids(n);
  for (int s = 0; s < n; ++s) {
    const Eigen::Vector3d& p = points[by_cell[s].second];
    xs[s] = p.x(), ys[s] = p.y(), zs[s] = p.z();
    keys[s] = by_cell[s].first;
    ids[s] = by_cell[s].second;
  }
  auto firstAtOrAfter = [&keys](int64_t k) {
    return static_cast<int>(std::lower_bound(keys.begin(), keys.end(), k) - keys.begin());
  };

  GridNeighbours result;
  result.begin.resize(n);
  result.count.resize(n);
  result.cutoff2.assign(n, std::numeric_limits<double>::infinity());
  const double r2 = radius * radius;
  const bool vector = scan != GridScan::kScalar;

  // Whole cells in chunks of about kChunkPoints, searched on either core: the registration
  // describes its two clouds side by side, and the core done with the smaller one takes the
  // other's chunks. Each chunk lists its points' neighbours apart; joined in cell order they are
  // the list one pass makes.
  constexpr int kChunkPoints = 256;
  std::vector<int> chunk_start;  // sorted positions where a chunk begins
  for (int s = 0; s < n;) {
    chunk_start.push_back(s);
    int e = std::min(n, s + kChunkPoints);
    while (e < n && keys[e] == keys[e - 1]) ++e;
    s = e;
  }
  chunk_start.push_back(n);
  const int chunks = static_cast<int>(chunk_start.size()) - 1;
  struct Chunk {
    std::vector<int> index;
    std::vector<double> distance2;
  };
  std::vector<Chunk> lists(chunks);

  auto searchChunk = [&](int chunk) {
    Chunk& out = lists[chunk];
    out.index.reserve(static_cast<size_t>(chunk_start[chunk + 1] - chunk_start[chunk]) *
                      std::min(max_neighbours, 128));
    out.distance2.reserve(out.index.capacity());
    std::vector<std::pair<int, int>> runs;
    std::vector<std::pair<double, int>> found;
    std::vector<double> found_distance2;  // the vector scans' output, then packed into `found`
    std::vector<int> found_id;
    for (int cell_begin = chunk_start[chunk]; cell_begin < chunk_start[chunk + 1];) {
      int cell_end = cell_begin;
      while (cell_end < n && keys[cell_end] == keys[cell_begin]) ++cell_end;
      // The nine runs: a run may take in a cell at the far end of the row before or after (x
      // wraps in the key), whose points the distance test then drops.
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
      size_t candidates = 0;
      for (const auto& [from, to] : runs) candidates += to - from;
      if (found.size() < candidates) found.resize(candidates);
      // Room for the three entries past the last that the four-wide scan writes (grid_scan.h).
      if (vector && found_id.size() < candidates + 3) {
        found_distance2.resize(candidates + 3);
        found_id.resize(candidates + 3);
      }
      for (int s = cell_begin; s < cell_end; ++s) {
        const double x = xs[s], y = ys[s], z = zs[s];
        size_t kept = 0;
        if (vector) {
          const auto scanRun = scan == GridScan::kAvx512 ? scanRunAvx512 : scanRunAvx2;
          for (const auto& [from, to] : runs) {
            kept = scanRun(xs.data(), ys.data(), zs.data(), ids.data(), from, to, x, y, z, r2,
                           found_distance2.data(), found_id.data(), kept);
          }
          for (size_t j = 0; j < kept; ++j) found[j] = {found_distance2[j], found_id[j]};
        } else {
          // Every candidate is written and only those within the radius kept (the count
          // advances by the comparison): a third of them are, a branch on it mispredicts at
          // random.
          for (const auto& [from, to] : runs) {
            for (int t = from; t < to; ++t) {
              const double dx = xs[t] - x, dy = ys[t] - y, dz = zs[t] - z;
              const double d = dx * dx + dy * dy + dz * dz;
              found[kept] = {d, ids[t]};
              kept += d < r2;
            }
          }
        }
        const auto found_end = found.begin() + kept;
        const size_t keep = std::min(kept, static_cast<size_t>(max_neighbours));
        const int i = by_cell[s].second;
        if (keep < kept) {
          std::nth_element(found.begin(), found.begin() + keep - 1, found_end);
          result.cutoff2[i] = found[keep - 1].first;
        }
        if (sorted) std::sort(found.begin(), found.begin() + keep);
        result.begin[i] = static_cast<int>(out.index.size());  // within the chunk, for now
        result.count[i] = static_cast<int>(keep);
        for (size_t j = 0; j < keep; ++j) {
          out.distance2.push_back(found[j].first);
          out.index.push_back(found[j].second);
        }
      }
      cell_begin = cell_end;
    }
  };
  tbb::parallel_for(0, chunks, searchChunk);

  // The chunks' lists one after the other, each point's start moved by its chunk's offset.
  std::vector<size_t> offset(chunks + 1, 0);
  for (int k = 0; k < chunks; ++k) offset[k + 1] = offset[k] + lists[k].index.size();
  result.index.resize(offset[chunks]);
  result.distance2.resize(offset[chunks]);
  tbb::parallel_for(0, chunks, [&](int k) {
    std::copy(lists[k].index.begin(), lists[k].index.end(), result.index.begin() + offset[k]);
    std::copy(lists[k].distance2.begin(), lists[k].distance2.end(),
              result.distance2.begin() + offset[k]);
    for (int s = chunk_start[k]; s < chunk_start[k + 1]; ++s) {
      result.begin[by_cell[s].second] += static_cast<int>(offset[k]);
    }
  });
  return result;
}

}  // namespace pnpba
