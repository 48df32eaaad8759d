// Private to the depth-only registration (registration.cpp): FPFH descriptors as Open3D's
// ComputeFPFHFeature defines them (Rusu et al. 2009: each point's histogram of pair features with
// its neighbours, 11 bins per feature, plus its neighbours' histograms weighted by 1 / squared
// distance), equal to Open3D's to round-off (tests/pipeline/fpfh_descriptors_test.cpp) at under
// half its cost: 70-90 ms a rendered room's cloud there, of which 40 ms or more went to dividing
// each of a neighbour's 33 bins by its distance where one reciprocal does, and 10-40 ms to a k-d
// tree radius search with every point's neighbours sorted, where a grid (grid_neighbours.h) and no
// sorting do; a pair of mutual neighbours is binned once for both. Where neighbours tie in distance
// at the 100th, the lower point number is kept (Open3D keeps its k-d tree's choice).
#pragma once

#include <Eigen/Core>

#include "cloud.h"

namespace pnpba {

// 33 x n, one descriptor per point of `cloud`, which must have normals. Neighbours: the
// max_neighbours nearest within `radius` (the point itself counted, as Open3D counts it).
// Throws std::invalid_argument without normals, for radius <= 0 or max_neighbours < 1.
// four_wide: the pair features (pair_bins.h) and the neighbours' weighted histograms
// (weighted_histograms.h) four at a time where the CPU has AVX2, the same descriptors to the
// last bit; false only to check that.
Eigen::Matrix<double, 33, Eigen::Dynamic> fpfhDescriptors(const Cloud& cloud, int max_neighbours,
                                                          double radius, bool four_wide = true);

}  // namespace pnpba
