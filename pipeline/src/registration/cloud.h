// Private to the depth-only registration (registration.cpp): a point cloud as the registration
// keeps it, in the frame of the camera that saw it. Open3D's PointCloud would do, but its
// library opens in 50-90 ms (about 100 shared libraries), more than the whole registration: the
// registration's own steps work on this, and only the optional Open3D steps
// (pipeline/plugin/open3d_steps.cpp) copy it into Open3D's type.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace pnpba {

struct Cloud {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> normals;  // empty, or one unit normal per point
};

}  // namespace pnpba
