// Private to the registration plugin: how many points Open3D's VoxelDownSample would return,
// without building them. The registration sizes its voxel from that count (past its point cap
// the voxel grows), and down-sampling a rendered room's whole cloud only to count it, then
// again at the grown voxel, kept one core busy while the other waited with cloud 2.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace pnpba {

// The number of distinct voxels of side `voxel` (> 0) that hold a point, on Open3D's grid: its
// origin half a voxel below the points' least corner, each point's index floor((p - origin) /
// voxel) per axis, as PointCloud::VoxelDownSample computes them. So it equals
// VoxelDownSample(voxel)->points_.size() for every cloud of finite points.
size_t occupiedVoxels(const std::vector<Eigen::Vector3d>& points, double voxel);

}  // namespace pnpba
