#include "fpfh.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include "angle_bin.h"
#include "grid_neighbours.h"

namespace pnpba {

namespace {

using Histogram = Eigen::Matrix<double, 33, 1>;

int clampedBin(double bin) {
  const int b = static_cast<int>(std::floor(bin));
  return b >= 11 ? 10 : std::max(0, b);
}

// The three bins of the pair (p1, n1) -> (p2, n2): Darboux frame on the point whose normal is
// nearer perpendicular to the line between them, then (theta, alpha, phi) as Open3D bins them.
// The pair (p2, n2) -> (p1, n1) puts the frame on the same point and gives the same bins to the
// last bit (d negated twice, dot products negated), unless the two normals make the same angle
// with the line (then both directions put it on their first point): `reversible` says which.
struct PairBins {
  int theta = 0, alpha = 0, phi = 0;
  bool reversible = true;
};

PairBins pairBins(const Eigen::Vector3d& p1, const Eigen::Vector3d& n1, const Eigen::Vector3d& p2,
                  const Eigen::Vector3d& n2) {
  double alpha = 0, phi = 0;
  int theta_bin = 5;  // an angle of 0
  bool reversible = true;
  Eigen::Vector3d d = p2 - p1;
  const double length = d.norm();
  if (length != 0) {
    const double cos1 = n1.dot(d) / length, cos2 = n2.dot(d) / length;
    // acos(|cos1|) > acos(|cos2|) exactly when |cos1| < |cos2|: acos is decreasing.
    const bool swap = std::abs(cos1) < std::abs(cos2);
    reversible = std::abs(cos1) != std::abs(cos2);
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
      theta_bin = fastAngleBin(w.dot(other), u.dot(other));
    }
  }
  return {theta_bin, 11 + clampedBin(11 * (alpha + 1.0) * 0.5),
          22 + clampedBin(11 * (phi + 1.0) * 0.5), reversible};
}

void addBins(const PairBins& bins, double increment, double* histogram) {
  histogram[bins.theta] += increment;
  histogram[bins.alpha] += increment;
  histogram[bins.phi] += increment;
}

// Whether i is among j's neighbours, given that j is among i's at squared distance d2 (the same
// both ways): always where j kept every point within the radius, else where d2 is below the
// farthest j kept; a tie with that one is looked up.
bool isNeighbourOf(const GridNeighbours& nb, int i, int j, double d2) {
  if (d2 != nb.cutoff2[j]) return d2 < nb.cutoff2[j];
  const auto first = nb.index.begin() + nb.begin[j];
  return std::find(first, first + nb.count[j], i) != first + nb.count[j];
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
  const GridNeighbours nb = nearestWithin(cloud.points_, radius, max_neighbours);

  // Each point's own histogram (SPFH): its pairs with every neighbour, 100 in each feature. A pair
  // of mutual neighbours is binned once, by the lower-numbered point, for both (the pair
  // features are most of the descriptors' cost).
  Eigen::Matrix<double, 33, Eigen::Dynamic> spfh = Eigen::MatrixXd::Zero(33, n);
  auto increment = [&nb](int i) { return 100.0 / (nb.count[i] - 1); };
  for (int i = 0; i < n; ++i) {
    const int begin = nb.begin[i], k = nb.count[i];
    if (k <= 1) continue;
    for (int j = 0; j < k; ++j) {
      const int q = nb.index[begin + j];
      if (q == i) continue;
      const bool mutual = isNeighbourOf(nb, i, q, nb.distance2[begin + j]);
      if (mutual && q < i) continue;  // binned for both when q's turn came
      const Eigen::Vector3d &p_i = cloud.points_[i], &p_q = cloud.points_[q];
      const Eigen::Vector3d &n_i = cloud.normals_[i], &n_q = cloud.normals_[q];
      const PairBins bins = pairBins(p_i, n_i, p_q, n_q);
      addBins(bins, increment(i), spfh.col(i).data());
      if (!mutual) continue;
      addBins(bins.reversible ? bins : pairBins(p_q, n_q, p_i, n_i), increment(q),
              spfh.col(q).data());
    }
  }
  // FPFH: the neighbours' histograms weighted by 1 / squared distance, each feature's share
  // scaled back to 100, plus the point's own.
  for (int i = 0; i < n; ++i) {
    const int begin = nb.begin[i], k = nb.count[i];
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
