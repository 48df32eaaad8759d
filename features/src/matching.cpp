#include "pnpba/features/matching.h"

#include <algorithm>
#include <opencv2/features2d.hpp>

#include "pnpba/core/error.h"

namespace pnpba {

const char* toString(MatchFilter filter) {
  switch (filter) {
    case MatchFilter::kTextbook:
      return "textbook";
    case MatchFilter::kRatio:
      return "ratio";
    case MatchFilter::kCrossCheck:
      return "cross-check";
  }
  return "?";
}

MatchFilter parseMatchFilter(const std::string& name) {
  for (MatchFilter f : {MatchFilter::kTextbook, MatchFilter::kRatio, MatchFilter::kCrossCheck}) {
    if (name == toString(f)) return f;
  }
  throw Error("unknown match filter '" + name + "' (expected textbook, ratio or cross-check)");
}

std::string MatchOptions::validate() const {
  if (!(ratio > 0 && ratio <= 1)) return "ratio must be in (0, 1]";
  if (max_distance < 0) return "max distance must be >= 0";
  return "";
}

std::vector<cv::DMatch> matchDescriptors(const cv::Mat& descriptors1, const cv::Mat& descriptors2,
                                         const MatchOptions& options) {
  const std::string problem = options.validate();
  if (!problem.empty()) throw Error(problem);
  std::vector<cv::DMatch> kept;
  if (descriptors1.empty() || descriptors2.empty()) return kept;
  cv::BFMatcher matcher(cv::NORM_HAMMING, options.filter == MatchFilter::kCrossCheck);

  switch (options.filter) {
    case MatchFilter::kTextbook: {
      std::vector<cv::DMatch> all;
      matcher.match(descriptors1, descriptors2, all);
      double min_dist = 10000;
      for (const cv::DMatch& m : all) min_dist = std::min<double>(min_dist, m.distance);
      for (const cv::DMatch& m : all) {
        if (m.distance <= std::max(2 * min_dist, 30.0)) kept.push_back(m);
      }
      break;
    }
    case MatchFilter::kRatio: {
      std::vector<std::vector<cv::DMatch>> knn;
      matcher.knnMatch(descriptors1, descriptors2, knn, 2);
      for (const auto& pair : knn) {
        if (pair.size() == 2 && pair[0].distance < options.ratio * pair[1].distance) {
          kept.push_back(pair[0]);
        } else if (pair.size() == 1) {
          kept.push_back(pair[0]);
        }
      }
      break;
    }
    case MatchFilter::kCrossCheck:
      matcher.match(descriptors1, descriptors2, kept);
      break;
  }
  if (options.max_distance > 0) {
    kept.erase(
        std::remove_if(kept.begin(), kept.end(),
                       [&](const cv::DMatch& m) { return m.distance > options.max_distance; }),
        kept.end());
  }
  std::sort(kept.begin(), kept.end(),
            [](const cv::DMatch& a, const cv::DMatch& b) { return a.queryIdx < b.queryIdx; });
  return kept;
}

}  // namespace pnpba
