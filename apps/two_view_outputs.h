// What pose_estimation_3d2d writes besides stdout: the JSON report, the matches image and the
// PLY of points and camera centres. Every file is written atomically.
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "pnpba/pipeline/two_view.h"

namespace pnpba {

void writeTwoViewJson(const std::string& path, const TwoViewResult& r, const std::string& ba_mode);
// Image 1 above image 2, inlier matches green, outliers red.
void writeMatchesPng(const std::string& path, const cv::Mat& image1, const cv::Mat& image2,
                     const TwoViewResult& r);
// ASCII PLY: inlier points (camera-1 frame) white, camera centres green (camera 1 at the
// origin, camera 2 at -R^T t).
void writeTwoViewPly(const std::string& path, const TwoViewResult& r);

}  // namespace pnpba
