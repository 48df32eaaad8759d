// Camera: the pinhole model with distortion, the depth scale and (optionally) the image size;
// loadable from an ORB-SLAM2-style RGB-D settings file:
//
//   %YAML:1.0
//   Camera.fx: 517.3      Camera.fy: 516.5      Camera.cx: 318.6      Camera.cy: 255.3
//   Camera.k1: 0.2624     Camera.k2: -0.9531    Camera.p1: -0.0054    Camera.p2: 0.0026
//   Camera.k3: 1.1633     Camera.width: 640     Camera.height: 480    DepthMapFactor: 5000.0
//
// (one key per line). Camera.fx/fy/cx/cy are required; distortion defaults to 0, the depth
// factor to 5000, the size to unknown (0). Other keys are ignored.
#pragma once

#include <string>

#include "pnpba/features/pinhole_camera.h"

namespace pnpba {

struct Camera {
  PinholeCamera pinhole;        // defaults: the textbook pair (520.9, 521.0, 325.1, 249.7)
  double depth_scale = 5000.0;  // depth value per metre
  int width = 0, height = 0;    // 0: not known
  std::string validate() const;
};

// Throws Error "<path>:<line>: <problem>" (or "<path>: <problem>").
Camera loadCameraYaml(const std::string& path);

}  // namespace pnpba
