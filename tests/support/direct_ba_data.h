// The direct-BA exercise data (shared/data/direct_ba) as a DirectBaProblem, for tests and
// benchmarks: poses, points and the 7 images read as grey.
#pragma once

#include <opencv2/imgcodecs.hpp>
#include <string>

#include "pnpba/direct/direct_ba.h"

namespace pnpba::test {

inline DirectBaProblem loadDirectBaExercise(const std::string& shared_data) {
  const std::string d = shared_data + "/direct_ba/";
  DirectBaProblem p;
  p.poses = readDirectPoses(d + "poses.txt");
  p.points = readDirectPoints(d + "points.txt");
  for (size_t k = 0; k < p.poses.size(); ++k) {
    const cv::Mat m = cv::imread(d + std::to_string(k) + ".png", cv::IMREAD_GRAYSCALE);
    auto image = std::make_shared<GrayImage>();
    image->width = m.cols, image->height = m.rows;
    image->pixels.assign(m.begin<uchar>(), m.end<uchar>());
    p.images.push_back(image);
  }
  return p;
}

}  // namespace pnpba::test
