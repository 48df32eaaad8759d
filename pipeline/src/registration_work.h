// The global registration's work, predicted before it runs: how many points its two clouds keep
// after its voxel grid. Its time grows with them (the descriptors with the points, their matching
// with the product): the rendered rooms keep 6400-6900 and take 31-35 ms, the real cabinet about
// 3600 and 11-15 ms. A time budget expects the registration's time per thousand predicted
// points (time_budget.h), so a small scene is not judged by a large one's time.
#pragma once

#include <opencv2/core/mat.hpp>

#include "pnpba/features/pinhole_camera.h"
#include "pnpba/pipeline/depth_registration.h"

namespace pnpba {

// The voxel rule is the registration's (registrationVoxel and the max_points growth in
// registration/registration.cpp, which counts the voxels of the whole back-projected cloud; a
// prediction before the registration runs must not build it): a change there belongs here too.
//
// Thousands of points the two clouds keep, estimated from the depths' surface areas (each
// pixel's footprint (z / f)^2, on every 8th pixel each way) over the voxel's face: the voxel by
// the registration's rule (a fraction of depth 1's median depth, at most voxel_m), both counts
// scaled down as the registration grows its voxel past max_points. Depths of 0 (holes) or beyond
// max_range_m count for nothing.
double predictedRegistrationKilopoints(const cv::Mat& depth1, const cv::Mat& depth2,
                                       const PinholeCamera& camera, double depth_scale,
                                       const DepthRegistrationOptions& options);

}  // namespace pnpba
