// A frame's features, found once where the frame takes part in several pairs: an odometry loop's
// frame is frame 2 of one pair and frame 1 of the next, and a sequence's evaluation pairs each
// frame with several others. estimateTwoView given them (two_view.h) skips their detection and
// answers exactly as it does without them; it refuses features found in another image or with
// other options, rather than pair the wrong keypoints.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "pnpba/features/orb_features.h"

namespace pnpba {

// A frame's features found with options other than its FrameFeatures' own (the SIFT retry's),
// and its depth as the depth registration described it, kept by the estimates given that frame
// for the pairs it takes part in next. Safe to use from several threads at once.
class LaterFeatures {
 public:
  // The features found with exactly these options, where an estimate kept them.
  std::optional<Features> find(const OrbOptions& options) const;
  // Keeps a copy (the first kept for the same options stays; at most kMaxKept option sets, the
  // retry's SIFT features of a 640 x 480 frame being about 1.5 MB).
  void keep(const OrbOptions& options, const Features& features);
  size_t size() const;
  static constexpr size_t kMaxKept = 4;

  // The frame's depth as frame 1 of a depth registration: its cloud, normals and descriptors,
  // opaque (the registration's plugin makes and reads them), under a key of the depth's pixels,
  // the camera and the registration's options (depth_registration.h). Null where none is kept.
  std::shared_ptr<const void> findDepth(uint64_t key) const;
  // Keeps it (shared, never copied; the first for a key stays; at most kMaxKept keys, a
  // description being about 1 MB).
  void keepDepth(uint64_t key, std::shared_ptr<const void> description);
  size_t depthSize() const;

 private:
  mutable std::mutex mutex_;
  std::vector<std::pair<OrbOptions, Features>> kept_;
  std::vector<std::pair<uint64_t, std::shared_ptr<const void>>> depths_;
};

struct FrameFeatures {
  Features features;
  OrbOptions options;        // what they were found with
  cv::Size size;             // the image's
  uint64_t fingerprint = 0;  // of the image's pixels (imageFingerprint)
  // The frame's SIFT retry features, found by the first estimate given this frame that retries
  // and taken by the next (an odometry loop's frame is in two pairs, a key frame in many), and
  // its depth's description by the first that registers the depths with it as frame 1.
  // Shared by this FrameFeatures' copies.
  std::shared_ptr<LaterFeatures> later = std::make_shared<LaterFeatures>();
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
