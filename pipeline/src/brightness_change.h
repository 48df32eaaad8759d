// Private to the pipeline: frame 2's brightness as an affine map of frame 1's, the change an
// auto exposure or a gain makes between two frames: i2 = (1 + gain) i1 + offset. The
// photometric residual I_2(uv) - I_1(u_1) (rgbd_residuals.h) then leaves
// value - gain i1 - offset, the part a pose can explain. With the offset alone (the median), a
// gain leaves a residual in proportion to the intensity, which the alignment explains by moving
// the pose along the image's gradients: on texture-poor frames, where the shading across a wall is
// most of the colour signal, centimetres.
#pragma once

#include <vector>

#include "rgbd_residuals.h"

namespace pnpba {

struct BrightnessChange {
  double gain = 0;    // i2 / i1 - 1
  double offset = 0;  // intensity units
  double sigma = 1;   // robust scale of what is left (robustSigmaOf's, at least the floor)
  double residual(const DenseResidual& r) const {
    return gain == 0 ? r.value - offset : r.value - gain * r.i1 - offset;
  }
};

// Fitted to the photometric residuals of `spans` (each a vector of them, in order) by
// Huber-weighted least squares: three reweighted passes from the median offset, each at the
// robust scale of the pass before (within 0.01 of the true gain with a tenth of the samples
// outliers: brightness_change_test.cpp). The gain has a Gaussian prior of 1-sigma gain_sigma, so
// that frames of one grey level, where gain and offset cannot be told apart, keep gain 0.
// gain_sigma 0: the median offset alone (the model before the gain), the same numbers as before it.
// *scratch: storage reused between calls.
BrightnessChange fitBrightnessChange(const std::vector<const std::vector<DenseResidual>*>& spans,
                                     double gain_sigma, double huber_sigmas, double sigma_floor,
                                     std::vector<double>* scratch);

}  // namespace pnpba
