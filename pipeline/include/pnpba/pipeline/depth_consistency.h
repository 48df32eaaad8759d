// How well a pose agrees with both depth images: depth-1 points moved by T_21 and projected
// into image 2 should land on the surface depth 2 sees there (and the same from image 2 into
// image 1 with T_21^-1). A point landing clearly IN FRONT of the observed surface contradicts
// the pose (camera 2 would have seen it); one landing behind may be occluded and says
// nothing. Consistency = agreeing / (agreeing + contradicting), over both directions.
#pragma once

#include <opencv2/core.hpp>

#include "pnpba/features/pinhole_camera.h"
#include "pnpba/optimize/se3_quat.h"

namespace pnpba {

struct DepthConsistency {
  int agree = 0, contradict = 0, checked = 0;  // checked: samples with a depth to compare
  double consistency() const {
    return agree + contradict > 0 ? static_cast<double>(agree) / (agree + contradict) : 0.0;
  }
};

// Samples every `stride`-th pixel. Tolerance per point: 2 cm + 2 k z^2 (k: depth noise, 1/m).
// Pixels are used as pinhole pixels (distortion is below the tolerance at this purpose).
DepthConsistency measureDepthConsistency(const cv::Mat& depth1, const cv::Mat& depth2,
                                         const SE3Quat& T_21, const PinholeCamera& camera,
                                         double depth_scale, int stride = 8,
                                         double noise_k = 0.003);

}  // namespace pnpba
