// The function the Open3D plugin (pipeline/plugin/open3d_registration.cpp) exports and
// depth_registration.cpp calls. Both are built together and share OpenCV's core, so the
// arguments are pnpba's own types by pointer; it does not throw.
#pragma once

#include <memory>

#include "pnpba/pipeline/depth_registration.h"

namespace pnpba {

inline constexpr const char* kOpen3dPlugin = "open3d";

// Depth 1 as the plugin describes it for a registration (its cloud, the voxel chosen from it,
// the down-sampled cloud's normals and descriptors), opaque to the caller: `given` one that an
// earlier registration of the same depth 1, camera and options made, or null; `made` set by the
// plugin where it described depth 1 itself, for the caller to keep.
struct Depth1Description {
  std::shared_ptr<const void> given;
  std::shared_ptr<const void> made;
};

// described1 may be null (nothing given, nothing kept).
using Open3dRegisterDepthImages = void(const cv::Mat* depth1, const cv::Mat* depth2,
                                       const PinholeCamera* camera, double depth_scale,
                                       const DepthRegistrationOptions* options,
                                       Depth1Description* described1, DepthRegistration* result);

}  // namespace pnpba
