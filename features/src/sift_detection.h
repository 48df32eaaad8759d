// OpenCV's SIFT detection, to the bit, on a scale space the descriptors then read too. OpenCV's
// detect builds the Gaussian scale space and keeps it to itself, so the descriptor kernel
// (sift_descriptors.h) had to build it again: about 4 ms of the 30 an image of the SIFT retry
// takes on one core. Here the scale space is built once (with OpenCV's own calls) and the
// keypoints found in it in OpenCV's arithmetic: its extrema, their refinement and orientations,
// fused where its AVX2 build fuses.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "sift_descriptors.h"

namespace pnpba {

// True where the keypoints below are OpenCV's to the bit: fastSiftDescriptorsAvailable(), and a
// CPU whose OpenCV runs its SIFT's AVX2 code (on one with AVX-512 it runs 16 lanes, whose
// scalar remainders may round differently).
bool siftDetectionAvailable();

// The scale space OpenCV's detect builds for `image` (8-bit grey or BGR): every octave, every
// layer.
SiftScaleSpace siftDetectionScaleSpace(const cv::Mat& image);

// The keypoints cv::SIFT::create(features, 3, contrast_threshold)->detect returns on the image
// `space` was built from (siftDetectionScaleSpace), every field equal. Requires
// siftDetectionAvailable().
std::vector<cv::KeyPoint> siftKeypoints(const SiftScaleSpace& space, int features,
                                        double contrast_threshold);

// detectAndCompute's keypoints and descriptors, from one scale space.
void siftDetectAndCompute(const cv::Mat& image, int features, double contrast_threshold,
                          std::vector<cv::KeyPoint>* keypoints, cv::Mat* descriptors);

}  // namespace pnpba
