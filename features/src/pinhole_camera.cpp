#include "pnpba/features/pinhole_camera.h"

#include <cmath>

namespace pnpba {

bool PinholeCamera::hasDistortion() const {
  for (double k : distortion) {
    if (k != 0.0) return true;
  }
  return false;
}

std::string PinholeCamera::validate() const {
  if (!std::isfinite(fx) || !(fx > 0)) return "fx must be finite and > 0";
  // A negative fy is a camera whose image rows run upwards (ICL-NUIM's convention).
  if (!std::isfinite(fy) || fy == 0) return "fy must be finite and non-zero";
  if (!std::isfinite(cx) || !std::isfinite(cy)) return "cx and cy must be finite";
  for (double k : distortion) {
    if (!std::isfinite(k)) return "distortion coefficients must be finite";
  }
  return "";
}

}  // namespace pnpba
