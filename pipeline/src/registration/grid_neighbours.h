// Private to the depth-only registration (registration.cpp): every point's nearest neighbours
// within a radius, found on a grid of radius-sized cells, for the FPFH descriptors (fpfh.h) and the
// normals (point_normals.h).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace pnpba {

// Point i's neighbours, itself among them, are entries begin[i] .. begin[i] + count[i] of
// `index` and `distance2`.
struct GridNeighbours {
  std::vector<int> begin, count, index;
  std::vector<double> distance2;
  // Point i's farthest kept squared distance where its list was cut at max_neighbours, else
  // infinity (it kept every point within the radius).
  std::vector<double> cutoff2;
};

// How the candidates are scanned: kBest picks the widest the CPU has; the others are there to
// check that each gives the scalar scan's neighbours to the last bit (grid_scan.h).
enum class GridScan { kBest, kScalar, kAvx2, kAvx512 };

// Whether this CPU can run that scan.
bool gridScanAvailable(GridScan scan);

// The max_neighbours nearest within `radius` (squared distance below radius^2, as nanoflann's
// radius search takes it), ties at the last one kept by lower point number. In no particular
// order, or `sorted` by distance (then by point number), as a k-d tree returns them.
GridNeighbours nearestWithin(const std::vector<Eigen::Vector3d>& points, double radius,
                             int max_neighbours, bool sorted = false,
                             GridScan scan = GridScan::kBest);

}  // namespace pnpba
