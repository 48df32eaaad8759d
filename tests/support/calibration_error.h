// One calibration parameter off, in calibrationSensitivity's order and units (fx, fy relative;
// cx, cy in pixels; the depth scale relative, depths read 1 + e times): the intrinsics an
// estimator is then told and the factor its depths are read with. The tests of the calibration
// term re-run an estimator through it and compare its shift with the term's prediction.
#pragma once

#include "pnpba/features/pinhole_camera.h"

namespace pnpba::test {

struct OffCalibration {
  PinholeCamera camera;
  double depth_factor = 1;
};

inline OffCalibration offCalibration(PinholeCamera camera, int parameter, double error) {
  double depth_factor = 1;
  switch (parameter) {
    case 0:
      camera.fx *= 1 + error;
      break;
    case 1:
      camera.fy *= 1 + error;
      break;
    case 2:
      camera.cx += error;
      break;
    case 3:
      camera.cy += error;
      break;
    default:
      depth_factor = 1 + error;
  }
  return {camera, depth_factor};
}

}  // namespace pnpba::test
