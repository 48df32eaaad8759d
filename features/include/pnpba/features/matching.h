// Brute-force Hamming matching of ORB descriptors (image 1 -> image 2) with a selectable
// filter:
//   kTextbook    keep distance <= max(2 * min distance, 30) (the textbook program's rule)
//   kRatio       Lowe's ratio test: best < ratio * second best
//   kCrossCheck  keep mutual nearest neighbours
// max_distance > 0 additionally caps the Hamming distance.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace pnpba {

enum class MatchFilter { kTextbook, kRatio, kCrossCheck };
const char* toString(MatchFilter filter);
MatchFilter parseMatchFilter(const std::string& name);  // throws Error

struct MatchOptions {
  MatchFilter filter = MatchFilter::kRatio;
  double ratio = 0.8;
  int max_distance = 0;  // 0: no cap
  std::string validate() const;
};

// queryIdx indexes descriptors1, trainIdx descriptors2; sorted by queryIdx.
std::vector<cv::DMatch> matchDescriptors(const cv::Mat& descriptors1, const cv::Mat& descriptors2,
                                         const MatchOptions& options);

}  // namespace pnpba
