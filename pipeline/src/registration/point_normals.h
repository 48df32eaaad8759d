// Private to the depth-only registration (registration.cpp): normals as Open3D's
// PointCloud::EstimateNormals with a hybrid search defines them, with the neighbours found on a
// grid (grid_neighbours.h) instead of a k-d tree (14 ms of a rendered room's 15 went to the
// search), and each covariance's eigenvector by Eigen's closed-form solver.
#pragma once

#include "cloud.h"

namespace pnpba {

// Sets cloud->normals: each point's covariance over its max_neighbours nearest within `radius`
// (summed nearest first, as a k-d tree returns them), and the unit eigenvector of its least
// eigenvalue; a point with fewer than 3 neighbours gets (0, 0, 1). Unoriented.
void estimateNormals(Cloud* cloud, double radius, int max_neighbours);

// Turns every normal to face the camera at the cloud's origin (a zero normal takes the direction
// to the camera), as Open3D's OrientNormalsTowardsCameraLocation(0) does.
void orientNormalsTowardsCamera(Cloud* cloud);

}  // namespace pnpba
