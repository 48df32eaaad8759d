// The depth-only registration's options and checks; the work is registration/registration.cpp's,
// with Open3D's own steps from a plugin (pipeline/plugin/open3d_steps.cpp) opened the first time
// a registration's options ask for one of them.
#include "pnpba/pipeline/depth_registration.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include "open3d_plugin_api.h"
#include "pnpba/core/error.h"
#include "pnpba/core/plugin.h"
#include "pnpba/pipeline/frame_features.h"
#include "registration/registration.h"
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

Open3dSteps open3dSteps() {
  Open3dSteps steps;
  steps.global_search =
      pluginFunction<Open3dGlobalSearch>(kOpen3dPlugin, "pnpba_open3d_global_search_v3");
  steps.icp = pluginFunction<Open3dIcp>(kOpen3dPlugin, "pnpba_open3d_icp_v3");
  steps.information =
      pluginFunction<Open3dInformation>(kOpen3dPlugin, "pnpba_open3d_information_v3");
  return steps;
}

// Depth 1's description's key: a digest of its pixels' digest, the camera and every option the
// description follows (the cloud's stride and range, the voxel's rule, the descriptors' kind and
// neighbours).
uint64_t depth1DescriptionKey(const cv::Mat& depth1, const PinholeCamera& camera,
                              double depth_scale, const DepthRegistrationOptions& o) {
  const bool open3d_feature =
      o.method == GlobalRegistration::kOpen3dRansac || o.method == GlobalRegistration::kFast;
  const uint64_t pixels = imageFingerprint(depth1);
  const double numbers[] = {camera.fx,
                            camera.fy,
                            camera.cx,
                            camera.cy,
                            camera.distortion[0],
                            camera.distortion[1],
                            camera.distortion[2],
                            camera.distortion[3],
                            camera.distortion[4],
                            depth_scale,
                            static_cast<double>(o.pixel_stride),
                            o.max_range_m,
                            o.voxel_m,
                            o.voxel_depth_fraction,
                            static_cast<double>(o.max_points),
                            static_cast<double>(o.fpfh_neighbours),
                            open3d_feature ? 1.0 : 0.0};
  unsigned char bytes[sizeof(pixels) + sizeof(numbers)];
  std::memcpy(bytes, &pixels, sizeof(pixels));
  std::memcpy(bytes + sizeof(pixels), numbers, sizeof(numbers));
  return imageFingerprint(cv::Mat(1, static_cast<int>(sizeof(bytes)), CV_8UC1, bytes));
}

}  // namespace

double preloadDepthRegistration() {
  if (pluginLoaded(kOpen3dPlugin)) return 0.0;
  const auto start = std::chrono::steady_clock::now();
  open3dSteps();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

DepthRegistration registerDepthImages(const cv::Mat& depth1, const cv::Mat& depth2,
                                      const PinholeCamera& camera, double depth_scale,
                                      const DepthRegistrationOptions& options,
                                      LaterFeatures* depth1_kept) {
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
  // A process's first registration that needs Open3D's steps opens the plugin (tens of ms);
  // timed apart so that a report can tell that one-time cost from the registration's own work.
  double load_ms = 0.0;
  Open3dSteps open3d;
  if (registrationNeedsOpen3d(o)) {
    const auto load_start = std::chrono::steady_clock::now();
    const bool opened_before = pluginLoaded(kOpen3dPlugin);
    open3d = open3dSteps();
    if (!opened_before) {
      load_ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - load_start)
              .count();
    }
  }
  DepthRegistration r;
  if (depth1_kept == nullptr) {
    registerDepthImagesHere(depth1, depth2, camera, depth_scale, o, open3d, nullptr, &r);
  } else {
    const uint64_t key = depth1DescriptionKey(depth1, camera, depth_scale, o);
    Depth1Description described{depth1_kept->findDepth(key), nullptr};
    registerDepthImagesHere(depth1, depth2, camera, depth_scale, o, open3d, &described, &r);
    depth1_kept->keepDepth(key, std::move(described.made));
  }
  r.plugin_load_ms = load_ms;
  return r;
}

}  // namespace pnpba
