#include "pnpba/pipeline/frame_features.h"

#include <cstring>
#include <string>

#include "pnpba/core/error.h"
#include "pnpba/core/heap_retention.h"

namespace pnpba {

namespace {

constexpr uint64_t kMultiplier = 0x9E3779B97F4A7C15ull;  // 2^64 / golden ratio, odd

inline uint64_t mix(uint64_t h, uint64_t word) {
  h = (h ^ word) * kMultiplier;
  return h ^ (h >> 29);
}

}  // namespace

uint64_t imageFingerprint(const cv::Mat& image) {
  // Four independent chains over a row's 8-byte words (one chain's multiplications wait on each
  // other), folded with the row's tail bytes, then the chains and the row into the digest.
  uint64_t digest =
      mix(mix(mix(0, static_cast<uint64_t>(image.cols)), static_cast<uint64_t>(image.rows)),
          static_cast<uint64_t>(image.type()));
  const size_t row_bytes = static_cast<size_t>(image.cols) * image.elemSize();
  for (int y = 0; y < image.rows; ++y) {
    const unsigned char* row = image.ptr<unsigned char>(y);
    uint64_t lane[4] = {1, 2, 3, 4};
    size_t i = 0;
    for (; i + 32 <= row_bytes; i += 32) {
      for (int k = 0; k < 4; ++k) {
        uint64_t word;
        std::memcpy(&word, row + i + 8 * k, 8);
        lane[k] = mix(lane[k], word);
      }
    }
    for (; i < row_bytes; ++i) lane[0] = mix(lane[0], row[i]);
    for (uint64_t l : lane) digest = mix(digest, l);
  }
  return digest;
}

std::optional<Features> LaterFeatures::find(const OrbOptions& options) const {
  const std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [found_with, features] : kept_) {
    if (found_with == options) return features;
  }
  return std::nullopt;
}

void LaterFeatures::keep(const OrbOptions& options, const Features& features) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (kept_.size() >= kMaxKept) return;
  for (const auto& kept : kept_) {
    if (kept.first == options) return;  // two estimates found the same at once
  }
  // The descriptors deep-copied: a caller's Features may share its cv::Mat with others.
  Features copy = features;
  copy.descriptors = features.descriptors.clone();
  kept_.emplace_back(options, std::move(copy));
}

size_t LaterFeatures::size() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return kept_.size();
}

std::shared_ptr<const void> LaterFeatures::findDepth(uint64_t key) const {
  const std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [kept_key, description] : depths_) {
    if (kept_key == key) return description;
  }
  return nullptr;
}

void LaterFeatures::keepDepth(uint64_t key, std::shared_ptr<const void> description) {
  if (!description) return;
  const std::lock_guard<std::mutex> lock(mutex_);
  if (depths_.size() >= kMaxKept) return;
  for (const auto& kept : depths_) {
    if (kept.first == key) return;  // two estimates described it at once
  }
  depths_.emplace_back(key, std::move(description));
}

size_t LaterFeatures::depthSize() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return depths_.size();
}

FrameFeatures describeFrame(const cv::Mat& image, const OrbOptions& options) {
  retainFreedHeapMemoryOnce();  // as estimateTwoView: the next frame reuses these pages
  FrameFeatures f;
  f.features = detectOrb(image, options);  // throws for a bad image or options
  f.options = options;
  f.size = image.size();
  f.fingerprint = imageFingerprint(image);
  return f;
}

void checkFrameFeatures(const FrameFeatures& given, const cv::Mat& image, const OrbOptions& options,
                        const std::string& what) {
  if (given.options != options) {
    throw Error(what +
                ": its frame features were found with other feature options than "
                "this estimate's");
  }
  if (given.size != image.size() || given.fingerprint != imageFingerprint(image)) {
    throw Error(what + ": its frame features were found in another image");
  }
}

}  // namespace pnpba
