#include "sift_descriptors.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "pnpba/core/cpu_features.h"
#include "pnpba/core/error.h"

namespace pnpba {

namespace {

// OpenCV's SIFT constants (sift.simd.hpp): the base blur, and the blur the camera is assumed
// to have given the image already.
constexpr double kSigma = 1.6;
constexpr float kInitialSigma = 0.5f;

// OpenCV's packed octave field: octave (signed byte), layer.
struct OctaveLayer {
  int octave, layer;
};
OctaveLayer unpack(const cv::KeyPoint& k) {
  const int octave = k.octave & 255;
  return {octave < 128 ? octave : (-128 | octave), (k.octave >> 8) & 255};
}

}  // namespace

int siftOctaveCount(cv::Size size) {
  return cvRound(std::log(2.0 * std::min(size.width, size.height)) / std::log(2.) - 2) + 1;
}

// By the calls detectAndCompute makes (createInitialImage, buildGaussianPyramid), so every pixel
// is its own.
SiftScaleSpace siftScaleSpace(const cv::Mat& image, int last_octave, int last_layer) {
  cv::Mat grey, grey_float;
  if (image.channels() == 3 || image.channels() == 4) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else {
    grey = image;
  }
  grey.convertTo(grey_float, CV_32F, 1, 0);
  // In float, as OpenCV's createInitialImage takes sigma (1.6f squared is not 2.56 rounded).
  const float sigma = static_cast<float>(kSigma);
  const float first_blur =
      std::sqrt(std::max(sigma * sigma - kInitialSigma * kInitialSigma * 4, 0.01f));
  cv::Mat doubled, base;
  cv::resize(grey_float, doubled, cv::Size(grey_float.cols * 2, grey_float.rows * 2), 0, 0,
             cv::INTER_LINEAR);
  cv::GaussianBlur(doubled, base, cv::Size(), first_blur, first_blur);

  constexpr int kLayers = kSiftLayersPerOctave;
  double blur[kLayers];
  blur[0] = kSigma;
  const double k = std::pow(2., 1. / kSiftOctaveLayers);
  for (int i = 1; i < kLayers; ++i) {
    const double previous = std::pow(k, static_cast<double>(i - 1)) * kSigma;
    const double total = previous * k;
    blur[i] = std::sqrt(total * total - previous * previous);
  }
  SiftScaleSpace space;
  space.octaves = last_octave + 2;                                 // from -1
  const int layers = std::max(last_layer, kSiftOctaveLayers) + 1;  // the next octave needs layer 3
  space.images.resize(static_cast<size_t>(space.octaves) * kLayers);
  for (int o = 0; o < space.octaves; ++o) {
    for (int i = 0; i < layers; ++i) {
      cv::Mat& out = space.images[o * kLayers + i];
      if (o == 0 && i == 0) {
        out = base;
      } else if (i == 0) {
        const cv::Mat& finer = space.images[(o - 1) * kLayers + kSiftOctaveLayers];
        cv::resize(finer, out, cv::Size(finer.cols / 2, finer.rows / 2), 0, 0, cv::INTER_NEAREST);
      } else {
        cv::GaussianBlur(space.images[o * kLayers + i - 1], out, cv::Size(), blur[i], blur[i]);
      }
    }
  }
  return space;
}

bool fastSiftDescriptorsAvailable() {
#if CV_VERSION_MAJOR == 4 && CV_VERSION_MINOR >= 4 && CV_VERSION_MINOR <= 6
  return cpuHasAvx2Fma();  // the CPU and the OS (the wide registers saved on a switch)
#else
  return false;
#endif
}

namespace {

// The last octave and layer `keypoints` were found in, checked against an image of `size`.
OctaveLayer lastOctaveAndLayer(const std::vector<cv::KeyPoint>& keypoints, cv::Size size) {
  const int octaves = siftOctaveCount(size);
  OctaveLayer last{-1, 0};
  for (const cv::KeyPoint& k : keypoints) {
    const OctaveLayer at = unpack(k);
    if (at.octave < -1 || at.octave + 1 >= octaves || at.layer > kSiftOctaveLayers + 2) {
      throw Error("SIFT keypoint outside the scale space (octave " + std::to_string(at.octave) +
                  ", layer " + std::to_string(at.layer) + ")");
    }
    last.octave = std::max(last.octave, at.octave);
    last.layer = std::max(last.layer, at.layer);
  }
  return last;
}

}  // namespace

cv::Mat siftDescriptors(const cv::Mat& image, const std::vector<cv::KeyPoint>& keypoints) {
  if (!fastSiftDescriptorsAvailable()) throw Error("the SIFT descriptor kernel needs AVX2 and FMA");
  if (keypoints.empty()) return cv::Mat(0, 128, CV_32F);
  if (image.depth() != CV_8U ||
      (image.channels() != 1 && image.channels() != 3 && image.channels() != 4)) {
    throw Error("SIFT descriptors need an 8-bit grey or colour image");
  }
  const OctaveLayer last = lastOctaveAndLayer(keypoints, image.size());
  return siftDescriptors(siftScaleSpace(image, last.octave, last.layer), keypoints);
}

cv::Mat siftDescriptors(const SiftScaleSpace& space, const std::vector<cv::KeyPoint>& keypoints) {
  if (!fastSiftDescriptorsAvailable()) throw Error("the SIFT descriptor kernel needs AVX2 and FMA");
  for (const cv::KeyPoint& k : keypoints) {
    const OctaveLayer at = unpack(k);
    const size_t index = static_cast<size_t>(at.octave + 1) * kSiftLayersPerOctave + at.layer;
    if (at.octave < -1 || at.layer > kSiftOctaveLayers + 2 || index >= space.images.size() ||
        space.images[index].empty()) {
      throw Error("SIFT keypoint outside the scale space (octave " + std::to_string(at.octave) +
                  ", layer " + std::to_string(at.layer) + ")");
    }
  }
  cv::Mat descriptors(static_cast<int>(keypoints.size()), 128, CV_32F);
  // Keypoints in chunks on TBB's workers, as OpenCV's parallel loop shares them.
  tbb::parallel_for(
      tbb::blocked_range<int>(0, descriptors.rows, 32), [&](const tbb::blocked_range<int>& range) {
        kernels::SiftScratch scratch;
        for (int i = range.begin(); i < range.end(); ++i) {
          const cv::KeyPoint& k = keypoints[i];
          const OctaveLayer at = unpack(k);
          const size_t index = static_cast<size_t>(at.octave + 1) * kSiftLayersPerOctave + at.layer;
          // Keypoints are in the image's pixels; octave o's are 2^-o of them.
          const float scale = at.octave >= 0 ? 1.f / static_cast<float>(1 << at.octave)
                                             : static_cast<float>(1 << -at.octave);
          float angle = 360.f - k.angle;
          if (std::abs(angle - 360.f) < FLT_EPSILON) angle = 0.f;
          kernels::siftDescriptorAvx2(space.images[index],
                                      cv::Point2f(k.pt.x * scale, k.pt.y * scale), angle,
                                      k.size * scale * 0.5f, descriptors.ptr<float>(i), &scratch);
        }
      });
  return descriptors;
}

}  // namespace pnpba
