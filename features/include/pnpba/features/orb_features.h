// ORB keypoints and descriptors (cv::ORB), for one image or for two images concurrently.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

namespace pnpba {

struct OrbOptions {
  // Defaults chosen by measured accuracy (docs/two_view.md "What each choice bought"): 1500 features on
  // 4 levels beat 1000 on 8 on real sequences; two views of one scene need little scale range.
  int num_features = 1500;
  float scale_factor = 1.2f;
  int levels = 4;
  int fast_threshold = 20;
  std::string validate() const;  // empty when valid
};

struct Features {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;  // one 32-byte row per keypoint
};

// Accepts 8-bit grey or BGR images; throws Error for an empty or other image.
Features detectOrb(const cv::Mat& image, const OrbOptions& options);
// Both images at once on two threads.
std::pair<Features, Features> detectOrbPair(const cv::Mat& image1, const cv::Mat& image2,
                                            const OrbOptions& options);

}  // namespace pnpba
