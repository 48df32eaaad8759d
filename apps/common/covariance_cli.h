// The covariance model's sensor sigmas as command-line options, the same in every tool that
// reports a covariance (pose_estimation_3d2d, evaluate_tum) and in covariance_bench.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdio>

#include "pnpba/pipeline/covariance_model.h"

namespace pnpba {

inline void addCovarianceOptions(CLI::App& app, CovarianceModelOptions& covariance) {
  app.add_option("--focal-sigma", covariance.focal_sigma,
                 "covariance: relative 1-sigma of the calibration's fx and fy")
      ->capture_default_str();
  app.add_option("--principal-point-sigma", covariance.principal_point_sigma_px,
                 "covariance: 1-sigma of cx and cy (px)")
      ->capture_default_str();
  app.add_option("--depth-scale-sigma", covariance.depth_scale_sigma,
                 "covariance: relative 1-sigma of the depth scale")
      ->capture_default_str();
  app.add_option("--motion-sigma", covariance.motion_sigma,
                 "covariance: unmodelled 1-sigma per axis as a fraction of the motion, levelling "
                 "off at the caps below (0 for rendered data)")
      ->capture_default_str();
  app.add_option("--motion-cap-deg", covariance.motion_cap_deg,
                 "covariance: the unmodelled rotation 1-sigma per axis levels off here (0: no cap)")
      ->capture_default_str();
  char cap_cm[32];  // shown as the default
  std::snprintf(cap_cm, sizeof cap_cm, "%g", covariance.motion_cap_m * 100.0);
  app.add_option_function<double>(
         "--motion-cap-cm", [&covariance](double cm) { covariance.motion_cap_m = cm / 100.0; },
         "covariance: the unmodelled translation 1-sigma per axis levels off here (0: no cap)")
      ->default_str(cap_cm);
  app.add_option("--fuse-agreeing", covariance.fuse_agreeing_poses,
                 "covariance: where the feature and the depth path agree (path both), report "
                 "their fused pose and covariance (false: the one kept, with its own)")
      ->capture_default_str();
}

}  // namespace pnpba
