#include "fpfh.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <utility>
#include <vector>

namespace pnpba {

namespace {

using Histogram = Eigen::Matrix<double, 33, 1>;

// Each point's nearest neighbours within a radius, itself among them: rows of a compressed
// table (row i is entries offsets[i] .. offsets[i + 1]).
struct Neighbours {
  std::vector<int> offsets, index;
  std::vector<double> distance2;
};

// On a grid of radius-sized cells, a point's neighbours are in the 27 cells around its own.
// A voxel-downsampled cloud has a few dozen points a cell, so this scans about a thousand
// candidates a point where a k-d tree's radius search (Open3D's nanoflann) walked and sorted
// for 10-40 ms a cloud.
Neighbours nearestWithin(const std::vector<Eigen::Vector3d>& points, double radius,
                         int max_neighbours) {
  const int n = static_cast<int>(points.size());
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
  // Points sorted by cell; each occupied cell's range found by binary search.
  std::vector<std::pair<int64_t, int>> by_cell(n);
  for (int i = 0; i < n; ++i) by_cell[i] = {key(cellOf(points[i])), i};
  std::sort(by_cell.begin(), by_cell.end());

  Neighbours result;
  result.offsets.reserve(n + 1);
  result.offsets.push_back(0);
  const double r2 = radius * radius;
  std::vector<std::pair<double, int>> found;
  for (int i = 0; i < n; ++i) {
    found.clear();
    const Eigen::Vector3i c = cellOf(points[i]);
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const Eigen::Vector3i m = c + Eigen::Vector3i(dx, dy, dz);
          if ((m.array() < 0).any() || (m.array() >= size.array()).any()) continue;
          const int64_t k = key(m);
          auto it = std::lower_bound(by_cell.begin(), by_cell.end(), std::make_pair(k, -1));
          for (; it != by_cell.end() && it->first == k; ++it) {
            const double d2 = (points[it->second] - points[i]).squaredNorm();
            if (d2 < r2) found.emplace_back(d2, it->second);
          }
        }
      }
    }
    // The nearest max_neighbours, in no particular order: only which they are matters (and the
    // order of a sum, to round-off).
    const size_t keep = std::min(found.size(), static_cast<size_t>(max_neighbours));
    if (keep < found.size()) std::nth_element(found.begin(), found.begin() + keep, found.end());
    for (size_t j = 0; j < keep; ++j) {
      result.distance2.push_back(found[j].first);
      result.index.push_back(found[j].second);
    }
    result.offsets.push_back(static_cast<int>(result.index.size()));
  }
  return result;
}

int clampedBin(double bin) {
  const int b = static_cast<int>(std::floor(bin));
  return b >= 11 ? 10 : std::max(0, b);
}

// The three bins of the pair (p1, n1) -> (p2, n2): Darboux frame on the point whose normal is
// nearer perpendicular to the line between them, then (theta, alpha, phi) as Open3D bins them.
void addPairFeature(const Eigen::Vector3d& p1, const Eigen::Vector3d& n1, const Eigen::Vector3d& p2,
                    const Eigen::Vector3d& n2, double increment, double* histogram) {
  double theta = 0, alpha = 0, phi = 0;
  Eigen::Vector3d d = p2 - p1;
  const double length = d.norm();
  if (length != 0) {
    const double cos1 = n1.dot(d) / length, cos2 = n2.dot(d) / length;
    // acos(|cos1|) > acos(|cos2|) exactly when |cos1| < |cos2|: acos is decreasing.
    const bool swap = std::abs(cos1) < std::abs(cos2);
    const Eigen::Vector3d& u = swap ? n2 : n1;
    const Eigen::Vector3d& other = swap ? n1 : n2;
    if (swap) d = -d;
    Eigen::Vector3d v = d.cross(u);
    const double v_norm = v.norm();
    if (v_norm != 0) {
      v /= v_norm;
      const Eigen::Vector3d w = u.cross(v);
      phi = swap ? -cos2 : cos1;
      alpha = v.dot(other);
      theta = std::atan2(w.dot(other), u.dot(other));
    }
  }
  histogram[clampedBin(11 * (theta + M_PI) / (2.0 * M_PI))] += increment;
  histogram[11 + clampedBin(11 * (alpha + 1.0) * 0.5)] += increment;
  histogram[22 + clampedBin(11 * (phi + 1.0) * 0.5)] += increment;
}

}  // namespace

Eigen::Matrix<double, 33, Eigen::Dynamic> fpfhDescriptors(const open3d::geometry::PointCloud& cloud,
                                                         int max_neighbours, double radius) {
  if (!cloud.HasNormals()) throw std::invalid_argument("FPFH descriptors need normals");
  if (!(radius > 0) || max_neighbours < 1) {
    throw std::invalid_argument("FPFH descriptors need a radius > 0 and a neighbour or more");
  }
  const int n = static_cast<int>(cloud.points_.size());
  Eigen::Matrix<double, 33, Eigen::Dynamic> fpfh = Eigen::MatrixXd::Zero(33, n);
  if (n == 0) return fpfh;
  const Neighbours nb = nearestWithin(cloud.points_, radius, max_neighbours);

  // Each point's own histogram (SPFH): its pairs with every neighbour, 100 in each feature.
  Eigen::Matrix<double, 33, Eigen::Dynamic> spfh = Eigen::MatrixXd::Zero(33, n);
  for (int i = 0; i < n; ++i) {
    const int begin = nb.offsets[i], k = nb.offsets[i + 1] - begin;
    if (k <= 1) continue;
    const double increment = 100.0 / (k - 1);
    for (int j = 0; j < k; ++j) {
      const int q = nb.index[begin + j];
      if (q == i) continue;
      addPairFeature(cloud.points_[i], cloud.normals_[i], cloud.points_[q], cloud.normals_[q],
                     increment, spfh.col(i).data());
    }
  }
  // FPFH: the neighbours' histograms weighted by 1 / squared distance, each feature's share
  // scaled back to 100, plus the point's own.
  for (int i = 0; i < n; ++i) {
    const int begin = nb.offsets[i], k = nb.offsets[i + 1] - begin;
    if (k <= 1) continue;
    Histogram weighted = Histogram::Zero();
    for (int j = 0; j < k; ++j) {
      const double d2 = nb.distance2[begin + j];
      if (d2 == 0.0) continue;  // the point itself (Open3D skips any point at distance 0)
      weighted.noalias() += (1.0 / d2) * spfh.col(nb.index[begin + j]);
    }
    for (int f = 0; f < 3; ++f) {
      const double sum = weighted.segment<11>(11 * f).sum();
      weighted.segment<11>(11 * f) *= sum != 0.0 ? 100.0 / sum : 0.0;
    }
    fpfh.col(i) = weighted + spfh.col(i);
  }
  return fpfh;
}

}  // namespace pnpba
