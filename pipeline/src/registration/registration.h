// Private to depth_registration.cpp: the depth-only registration's work, once its options and
// images are checked (depth_registration.h says what it computes).
#pragma once

#include <memory>
#include <opencv2/core.hpp>

#include "../open3d_plugin_api.h"
#include "pnpba/pipeline/depth_registration.h"

namespace pnpba {

// True where the options ask for a step of Open3D's own (Open3dSteps): its RANSAC or fast global
// registration, ICP, or the registration's covariance.
bool registrationNeedsOpen3d(const DepthRegistrationOptions& options);

// Depth 1 as the registration describes it (its cloud, the voxel chosen from it, the
// down-sampled cloud's normals and descriptors), opaque to the caller: `given` one that an
// earlier registration of the same depth 1, camera and options made, or null; `made` set where
// the registration described depth 1 itself, for the caller to keep.
struct Depth1Description {
  std::shared_ptr<const void> given;
  std::shared_ptr<const void> made;
};

// `open3d` holds the plugin's steps where registrationNeedsOpen3d(options); described1 may be
// null (nothing given, nothing kept). Depth is CV_16UC1, the options valid.
void registerDepthImagesHere(const cv::Mat& depth1, const cv::Mat& depth2,
                             const PinholeCamera& camera, double depth_scale,
                             const DepthRegistrationOptions& options, const Open3dSteps& open3d,
                             Depth1Description* described1, DepthRegistration* result);

}  // namespace pnpba
