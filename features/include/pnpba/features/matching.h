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

// The brute-force kernels behind the nearest-neighbour filters (kTextbook, kRatio), one per
// instruction set. Every kernel gives the same matches as OpenCV's BFMatcher (the first of equal
// distances keeps its place), so the choice changes only the time; kFastest, the default, is the
// fastest this CPU runs. The others are there to be compared (tests, benchmarks).
enum class MatchKernel { kFastest, kAvx512, kAvx2, kScalar };
bool hasMatchKernel(MatchKernel kernel);  // whether this CPU runs it

// queryIdx indexes descriptors1, trainIdx descriptors2; sorted by queryIdx. Throws Error for
// invalid options or a kernel the CPU does not run.
std::vector<cv::DMatch> matchDescriptors(const cv::Mat& descriptors1, const cv::Mat& descriptors2,
                                         const MatchOptions& options,
                                         MatchKernel kernel = MatchKernel::kFastest);

}  // namespace pnpba
