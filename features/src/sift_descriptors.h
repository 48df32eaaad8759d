// OpenCV's SIFT descriptors, to the bit, in a third of the time: its detectAndCompute spends
// three quarters of a 640 x 480 image's SIFT on the descriptors (about 24 us each, most of it
// adding each sample's eight weights into the histogram one float at a time). Here the Gaussian
// scale space is built with OpenCV's own calls (once for the detection and the descriptors, by
// sift_detection.h, or again for keypoints OpenCV found), and each descriptor is computed in the
// same arithmetic, in the same order, with vector instructions (AVX2).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace pnpba {

// True where the vector kernel runs (the CPU has AVX2 and FMA, and OpenCV is a version whose
// descriptors the kernel reproduces, 4.4-4.6); elsewhere use OpenCV's detectAndCompute.
bool fastSiftDescriptorsAvailable();

// The descriptors OpenCV's SIFT (3 layers an octave, sigma 1.6, its image doubled first)
// computes for `keypoints` as its detect returned them on `image` (8-bit grey or BGR): CV_32F,
// one row of 128 whole numbers 0-255 a keypoint, equal to detectAndCompute's. Requires
// fastSiftDescriptorsAvailable().
cv::Mat siftDescriptors(const cv::Mat& image, const std::vector<cv::KeyPoint>& keypoints);

// OpenCV's SIFT scale space: 3 layers an octave, 6 Gaussian images each.
constexpr int kSiftOctaveLayers = 3;
constexpr int kSiftLayersPerOctave = kSiftOctaveLayers + 3;

// The octaves OpenCV's SIFT builds for an image of `size` (its nOctaves, from octave -1).
int siftOctaveCount(cv::Size size);

// OpenCV's Gaussian scale space of an image, its image doubled first (octave -1), pixel for
// pixel: octave o's layer i at images[(o + 1) * kSiftLayersPerOctave + i], for octaves
// -1 .. last_octave and layers 0 .. max(last_layer, 3); the rest empty.
struct SiftScaleSpace {
  std::vector<cv::Mat> images;
  int octaves = 0;  // built, from -1
};
SiftScaleSpace siftScaleSpace(const cv::Mat& image, int last_octave, int last_layer);

// The same descriptors from a scale space already built (the detection's, sift_detection.h).
cv::Mat siftDescriptors(const SiftScaleSpace& space, const std::vector<cv::KeyPoint>& keypoints);

namespace kernels {

// Working memory of one thread's descriptors (the window's samples), kept between keypoints.
struct SiftScratch {
  std::vector<float> samples;
};

// One descriptor: `octave_image` is the scale-space image the keypoint was found in (CV_32F),
// `point` and `scale` in its pixels, `angle` the descriptor's orientation in degrees.
void siftDescriptorAvx2(const cv::Mat& octave_image, cv::Point2f point, float angle, float scale,
                        float* out, SiftScratch* scratch);

}  // namespace kernels

}  // namespace pnpba
