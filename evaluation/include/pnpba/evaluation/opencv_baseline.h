// The baseline a careful OpenCV user writes, for side-by-side evaluation: cv::ORB (same count),
// BFMatcher kNN with Lowe's ratio test, keypoints undistorted with cv::undistortPoints, depth 1
// at the raw keypoint, cv::solvePnPRansac(SOLVEPNP_EPNP) and cv::solvePnPRefineLM on the
// inliers. Nothing of pnpba's own front end or BA is used.
#pragma once

#include <opencv2/core.hpp>

#include "pnpba/pipeline/two_view.h"

namespace pnpba {

struct OpenCvBaselineOptions {
  int features = 1000;
  double ratio = 0.8;
  double threshold_px = 3.0;
  int iterations = 100;  // solvePnPRansac's default
  double confidence = 0.99;
};

// Fills T_21, T_init (RANSAC pose), counts, times and ok/failure of a TwoViewResult.
TwoViewResult estimateTwoViewOpenCv(const cv::Mat& image1, const cv::Mat& depth1,
                                    const cv::Mat& image2, const Camera& camera,
                                    const OpenCvBaselineOptions& options);

}  // namespace pnpba
