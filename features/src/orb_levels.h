// Private to pnpba::features: cv::ORB's keypoints and descriptors of one image, to the bit, with
// its pyramid levels detected as separate tasks that either core may take.
//
// cv::ORB treats its levels independently: each level's keypoints come from that level's image
// alone (FAST, the border cut, the Harris cull to the level's share, the orientation, and the
// descriptor on the blurred level). One image per core left a pair waiting on the slower core
// whenever the machine's second core was shared with other work; eight level tasks for the pair's
// two images let the faster core take more of them.
#pragma once

#include <opencv2/core.hpp>

#include "pnpba/features/orb_features.h"

namespace pnpba {

// What cv::ORB::create(num_features, scale_factor, levels, 31, 0, 2, HARRIS_SCORE, 31,
// fast_threshold)->detectAndCompute(image) returns, keypoints in the same order (level by level),
// for an 8-bit grey or BGR image.
Features orbByLevel(const cv::Mat& image, const OrbOptions& options);

}  // namespace pnpba
