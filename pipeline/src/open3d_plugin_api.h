// The function the Open3D plugin (pipeline/plugin/open3d_registration.cpp) exports and
// depth_registration.cpp calls. Both are built together and share OpenCV's core, so the
// arguments are pnpba's own types by pointer; it does not throw.
#pragma once

#include "pnpba/pipeline/depth_registration.h"

namespace pnpba {

inline constexpr const char* kOpen3dPlugin = "open3d";

using Open3dRegisterDepthImages = void(const cv::Mat* depth1, const cv::Mat* depth2,
                                       const PinholeCamera* camera, double depth_scale,
                                       const DepthRegistrationOptions* options,
                                       DepthRegistration* result);

}  // namespace pnpba
