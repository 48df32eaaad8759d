#include "orb_levels.h"

#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/parallel_invoke.h>

#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace pnpba {

namespace {

constexpr int kEdgeThreshold = 31;
constexpr int kPatchSize = 31;

// A level's scale as cv::ORB computes it: its float factor, widened, raised in double, narrowed
// (1.2f to the third is 1.7280002f, where 1.2 cubed in double rounds to 1.728f).
float levelScale(int level, float scale_factor) {
  return static_cast<float>(
      std::pow(static_cast<double>(scale_factor), static_cast<double>(level)));
}

// Each level's share of the features, as cv::ORB splits them: a geometric series rounded level by
// level in float, the last level taking what is left.
std::vector<int> featuresPerLevel(int features, float scale_factor, int levels) {
  std::vector<int> share(levels);
  const float factor = static_cast<float>(1.0 / static_cast<double>(scale_factor));
  float per_scale =
      features * (1 - factor) /
      (1 - static_cast<float>(std::pow(static_cast<double>(factor), static_cast<double>(levels))));
  int sum = 0;
  for (int level = 0; level < levels - 1; ++level) {
    share[level] = cvRound(per_scale);
    sum += share[level];
    per_scale *= factor;
  }
  share[levels - 1] = std::max(features - sum, 0);
  return share;
}

}  // namespace

Features orbByLevel(const cv::Mat& image, const OrbOptions& options) {
  cv::Mat grey = image;
  if (image.type() != CV_8UC1) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  const int levels = options.levels;
  const std::vector<int> share =
      featuresPerLevel(options.num_features, options.scale_factor, levels);
  std::vector<cv::Mat> pyramid(levels);
  std::vector<float> scale(levels);
  pyramid[0] = grey;
  scale[0] = 1.0f;
  // Each level by cv::ORB on that level alone with that level's share: the same FAST, culls,
  // angles and descriptors, at the level's own coordinates.
  std::vector<Features> found(levels);
  auto detectLevel = [&](int level) {
    if (share[level] == 0) return;  // cv::ORB culls such a level to nothing
    const cv::Ptr<cv::ORB> orb =
        cv::ORB::create(share[level], options.scale_factor, 1, kEdgeThreshold, 0, 2,
                        cv::ORB::HARRIS_SCORE, kPatchSize, options.fast_threshold);
    Features& f = found[level];
    orb->detectAndCompute(pyramid[level], cv::noArray(), f.keypoints, f.descriptors);
    // Back to the image's pixels, as cv::ORB labels and scales a level's keypoints.
    for (cv::KeyPoint& k : f.keypoints) {
      k.octave = level;
      k.size = kPatchSize * scale[level];
      k.pt *= scale[level];
    }
  };
  // Level 0, the image itself and about 40 % of the work, starts at once; the other core builds
  // the coarser levels meanwhile and takes them in turn (an odometry loop's one new image: its
  // level 0 had waited for the whole pyramid).
  tbb::parallel_invoke(
      [&] { detectLevel(0); },
      [&] {
        // The pyramid as cv::ORB builds it: each level from the last, by INTER_LINEAR_EXACT,
        // to the image's size over the level's scale, rounded (cv::ORB divides in float: the
        // pixel count over the float scale).
        for (int level = 1; level < levels; ++level) {
          scale[level] = levelScale(level, options.scale_factor);
          const cv::Size size(cvRound(grey.cols / scale[level]), cvRound(grey.rows / scale[level]));
          cv::resize(pyramid[level - 1], pyramid[level], size, 0, 0, cv::INTER_LINEAR_EXACT);
        }
        tbb::parallel_for(1, levels, detectLevel);
      });
  Features all;
  std::vector<cv::Mat> rows;
  for (Features& f : found) {
    all.keypoints.insert(all.keypoints.end(), f.keypoints.begin(), f.keypoints.end());
    if (!f.descriptors.empty()) rows.push_back(f.descriptors);
  }
  if (!rows.empty()) cv::vconcat(rows, all.descriptors);
  return all;
}

}  // namespace pnpba
