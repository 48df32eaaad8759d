// The depth-only registration's options and checks; the work is done by Open3D in a plugin
// (pipeline/plugin/open3d_registration.cpp), loaded the first time a pair needs it.
#include "pnpba/pipeline/depth_registration.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "open3d_plugin_api.h"
#include "pnpba/core/error.h"
#include "pnpba/core/plugin.h"
#include "two_view_stages.h"

namespace pnpba {

const char* toString(GlobalRegistration method) {
  switch (method) {
    case GlobalRegistration::kRansac:
      return "ransac";
    case GlobalRegistration::kOpen3dRansac:
      return "open3d-ransac";
    case GlobalRegistration::kFast:
      return "fast";
    case GlobalRegistration::kCandidates:
      return "candidates";
  }
  return "?";
}

GlobalRegistration parseGlobalRegistration(const std::string& name) {
  for (GlobalRegistration m : {GlobalRegistration::kRansac, GlobalRegistration::kOpen3dRansac,
                               GlobalRegistration::kFast, GlobalRegistration::kCandidates}) {
    if (name == toString(m)) return m;
  }
  throw Error("unknown global registration '" + name +
              "' (ransac, open3d-ransac, fast, candidates)");
}

std::string DepthRegistrationOptions::validate() const {
  if (!(voxel_m > 0) || !std::isfinite(voxel_m)) return "registration voxel must be > 0";
  if (!(voxel_depth_fraction >= 0) || !std::isfinite(voxel_depth_fraction)) {
    return "registration voxel depth fraction must be >= 0";
  }
  if (!(fine_voxel_m >= 0) || !std::isfinite(fine_voxel_m)) {
    return "registration fine voxel must be >= 0 (0: no fine stage)";
  }
  if (!(max_range_m > 0.1)) return "registration max range must be > 0.1 m";
  if (pixel_stride < 1) return "registration pixel stride must be >= 1";
  if (max_points != 0 && max_points < 100) {
    return "registration max points must be >= 100 (0: no limit)";
  }
  if (fpfh_neighbours < 5) return "registration FPFH neighbours must be >= 5";
  if (ransac_iterations < 1) return "registration RANSAC iterations must be >= 1";
  if (icp_iterations < 0) return "registration ICP iterations must be >= 0 (0: none)";
  if (!(ransac_confidence > 0 && ransac_confidence < 1)) {
    return "registration confidence must be in (0, 1)";
  }
  return candidates.validate();
}

namespace {

Open3dRegisterDepthImages* registrationFunction() {
  return pluginFunction<Open3dRegisterDepthImages>(kOpen3dPlugin,
                                                   "pnpba_open3d_register_depth_images");
}

}  // namespace

double preloadDepthRegistration() {
  if (pluginLoaded(kOpen3dPlugin)) return 0.0;
  const auto start = std::chrono::steady_clock::now();
  registrationFunction();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

DepthRegistration registerDepthImages(const cv::Mat& depth1, const cv::Mat& depth2,
                                      const PinholeCamera& camera, double depth_scale,
                                      const DepthRegistrationOptions& options) {
  const std::string problem = options.validate();
  if (!problem.empty()) throw Error(problem);
  if (depth1.type() != CV_16UC1 || depth2.type() != CV_16UC1) {
    throw Error("depth registration needs two 16-bit single-channel depth images");
  }
  // The stride is 640 x 480's: a larger image back-projects about as many points.
  DepthRegistrationOptions o = options;
  o.pixel_stride =
      std::max(options.pixel_stride,
               static_cast<int>(std::lround(options.pixel_stride / workingScale(depth1.size()))));
  static auto* registration = registrationFunction();
  DepthRegistration r;
  registration(&depth1, &depth2, &camera, depth_scale, &o, &r);
  return r;
}

}  // namespace pnpba
