// Private to the Open3D plugin: Open3D's normal estimation (PointCloud::EstimateNormals with a
// hybrid search) with the neighbours found on a grid (grid_neighbours.h) instead of a k-d tree:
// the same normals at a fraction of the cost (14 ms of a rendered room's 15 went to the search).
#pragma once

#include <open3d/geometry/PointCloud.h>

namespace pnpba {

// Sets cloud.normals_ as EstimateNormals(KDTreeSearchParamHybrid(radius, max_neighbours)) does:
// each point's covariance over its max_neighbours nearest within `radius` (summed nearest first,
// as the k-d tree returns them, so that the sums round alike; fewer than 3: the identity), and
// Open3D's own eigenvector of it. Unoriented, as Open3D leaves them.
void estimateNormals(open3d::geometry::PointCloud* cloud, double radius, int max_neighbours);

}  // namespace pnpba
