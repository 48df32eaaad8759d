#include "fpfh.h"

#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include "grid_neighbours.h"
#include "pair_bins.h"
#include "pnpba/core/cpu_features.h"
#include "weighted_histograms.h"

namespace pnpba {

namespace {

using Histogram = Eigen::Matrix<double, 33, 1>;

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

Eigen::Matrix<double, 33, Eigen::Dynamic> fpfhDescriptors(const Cloud& cloud, int max_neighbours,
                                                          double radius, bool four_wide) {
  if (cloud.points.empty() || cloud.normals.size() != cloud.points.size())
    throw std::invalid_argument("FPFH descriptors need normals");
  if (!(radius > 0) || max_neighbours < 1) {
    throw std::invalid_argument("FPFH descriptors need a radius > 0 and a neighbour or more");
  }
  const int n = static_cast<int>(cloud.points.size());
  Eigen::Matrix<double, 33, Eigen::Dynamic> fpfh = Eigen::MatrixXd::Zero(33, n);
  if (n == 0) return fpfh;
  const GridNeighbours nb = nearestWithin(cloud.points, radius, max_neighbours);

  // Each point's own histogram (SPFH): its pairs with every neighbour, 100 in each feature. A pair
  // of mutual neighbours is binned once, by the lower-numbered point, for both (the pair
  // features are most of the descriptors' cost).
  Eigen::Matrix<double, 33, Eigen::Dynamic> spfh = Eigen::MatrixXd::Zero(33, n);
  // Each point's share of 100 per pair, divided once per point rather than once per pair.
  std::vector<double> increment(n, 0.0);
  for (int i = 0; i < n; ++i) {
    if (nb.count[i] > 1) increment[i] = 100.0 / (nb.count[i] - 1);
  }
  const auto& points = cloud.points;
  const auto& normals = cloud.normals;
  const bool avx2 = four_wide && cpuHasAvx2Fma();
  // Per point: the pairs it bins, their bins (four at a time where AVX2 runs), then the
  // histograms' additions in the order the pairs come, as one pair at a time would make them.
  std::vector<int> partner;
  std::vector<char> partner_mutual;
  std::vector<PairBins> bins;
  for (int i = 0; i < n; ++i) {
    const int begin = nb.begin[i], k = nb.count[i];
    if (k <= 1) continue;
    // Every neighbour written, and kept by advancing the count: the point itself, and a mutual
    // neighbour binned for both when its turn came (q < i), are left out. Whether q < i is as
    // random as the cloud's order, and a branch on it mispredicted half the time.
    partner.resize(k);
    partner_mutual.resize(k);
    int m = 0;
    for (int j = 0; j < k; ++j) {
      const int q = nb.index[begin + j];
      const bool mutual = isNeighbourOf(nb, i, q, nb.distance2[begin + j]);
      partner[m] = q;
      partner_mutual[m] = mutual;
      m += static_cast<int>(q != i) & static_cast<int>(!(mutual && q < i));
    }
    bins.resize(m);
    int first_scalar = 0;
    if (avx2) {
      for (; first_scalar + 4 <= m; first_scalar += 4) {
        const double* p2[4];
        const double* n2[4];
        for (int l = 0; l < 4; ++l) {
          p2[l] = points[partner[first_scalar + l]].data();
          n2[l] = normals[partner[first_scalar + l]].data();
        }
        const int left =
            pairBinsAvx2(points[i].data(), normals[i].data(), p2, n2, bins.data() + first_scalar);
        for (int l = 0; l < 4; ++l) {
          if (!(left & (1 << l))) continue;
          const int q = partner[first_scalar + l];
          bins[first_scalar + l] = pairBins(points[i], normals[i], points[q], normals[q]);
        }
      }
    }
    for (int l = first_scalar; l < m; ++l) {
      bins[l] = pairBins(points[i], normals[i], points[partner[l]], normals[partner[l]]);
    }
    for (int l = 0; l < m; ++l) {
      const int q = partner[l];
      addBins(bins[l], increment[i], spfh.col(i).data());
      if (!partner_mutual[l]) continue;
      addBins(bins[l].reversible ? bins[l] : pairBins(points[q], normals[q], points[i], normals[i]),
              increment[q], spfh.col(q).data());
    }
  }
  // FPFH: the neighbours' histograms weighted by 1 / squared distance, each feature's share
  // scaled back to 100, plus the point's own. Each point's column alone: in blocks that the other
  // core takes when it has finished its own cloud (the registration describes its two clouds side
  // by side, and they are seldom the same size); the same sums on any thread.
  constexpr int kBlock = 256;
  tbb::parallel_for(0, (n + kBlock - 1) / kBlock, [&](int block) {
    for (int i = block * kBlock; i < std::min(n, (block + 1) * kBlock); ++i) {
      const int begin = nb.begin[i], k = nb.count[i];
      if (k <= 1) continue;
      Histogram weighted = Histogram::Zero();
      if (avx2) {
        weightedHistogramSumAvx2(spfh.data(), nb.index.data() + begin, nb.distance2.data() + begin,
                                 k, weighted.data());
      } else {
        for (int j = 0; j < k; ++j) {
          const double d2 = nb.distance2[begin + j];
          if (d2 == 0.0) continue;  // the point itself (Open3D skips any point at distance 0)
          weighted.noalias() += (1.0 / d2) * spfh.col(nb.index[begin + j]);
        }
      }
      for (int f = 0; f < 3; ++f) {
        const double sum = weighted.segment<11>(11 * f).sum();
        weighted.segment<11>(11 * f) *= sum != 0.0 ? 100.0 / sum : 0.0;
      }
      fpfh.col(i) = weighted + spfh.col(i);
    }
  });
  return fpfh;
}

}  // namespace pnpba
