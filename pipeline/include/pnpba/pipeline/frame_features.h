// A frame's features, found once where the frame takes part in several pairs: an odometry loop's
// frame is frame 2 of one pair and frame 1 of the next, and a sequence's evaluation pairs each
// frame with several others. estimateTwoView given them (two_view.h) skips their detection and
// answers exactly as it does without them; it refuses features found in another image or with
// other options, rather than pair the wrong keypoints.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

#include "pnpba/features/orb_features.h"

namespace pnpba {

struct FrameFeatures {
  Features features;
  OrbOptions options;        // what they were found with
  cv::Size size;             // the image's
  uint64_t fingerprint = 0;  // of the image's pixels (imageFingerprint)
};

// The first pass's features of `image` (8-bit grey or colour) as estimateTwoView finds them
// with these options. Throws Error for an empty or unsupported image or invalid options.
FrameFeatures describeFrame(const cv::Mat& image, const OrbOptions& options);

// A 64-bit digest of the image's size, type and every pixel, to tell a caller's mix-up of frames
// (not a cryptographic hash: a deliberate collision is easy to make). About 0.08 ms for a
// 640 x 480 colour image.
uint64_t imageFingerprint(const cv::Mat& image);

// Throws Error "<what>: ..." unless `given` was described from `image` with `options`.
void checkFrameFeatures(const FrameFeatures& given, const cv::Mat& image, const OrbOptions& options,
                        const std::string& what);

}  // namespace pnpba
