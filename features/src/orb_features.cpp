#include "pnpba/features/orb_features.h"

#include <oneapi/tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "orb_levels.h"
#include "pnpba/core/error.h"
#include "sift_descriptors.h"
#include "sift_detection.h"

namespace pnpba {

const char* toString(Detector detector) {
  switch (detector) {
    case Detector::kSift:
      return "sift";
    case Detector::kAkaze:
      return "akaze";
    case Detector::kOrb:
      break;
  }
  return "orb";
}

Detector parseDetector(const std::string& name) {
  for (Detector d : {Detector::kOrb, Detector::kSift, Detector::kAkaze}) {
    if (name == toString(d)) return d;
  }
  throw Error("unknown detector '" + name + "' (expected orb, sift or akaze)");
}

std::string OrbOptions::validate() const {
  if (num_features < 8) return "features must be >= 8";
  if (!(scale_factor > 1.0f)) return "scale factor must be > 1";
  if (levels < 1) return "levels must be >= 1";
  if (fast_threshold < 1) return "FAST threshold must be >= 1";
  if (sift_first_octave < -1 || sift_first_octave > 4) return "SIFT first octave must be -1 .. 4";
  if (!(sift_octave_fraction > 0.5 && sift_octave_fraction <= 1)) {
    return "SIFT octave fraction must be in (0.5, 1]";
  }
  if (!(sift_contrast_threshold > 0)) return "SIFT contrast threshold must be > 0";
  if (max_pixels < 0) return "max pixels must be >= 0 (0: no limit)";
  return "";
}

bool operator==(const OrbOptions& a, const OrbOptions& b) {
  return a.detector == b.detector && a.num_features == b.num_features &&
         a.scale_factor == b.scale_factor && a.levels == b.levels &&
         a.fast_threshold == b.fast_threshold && a.sift_first_octave == b.sift_first_octave &&
         a.sift_octave_fraction == b.sift_octave_fraction &&
         a.sift_contrast_threshold == b.sift_contrast_threshold && a.max_pixels == b.max_pixels;
}

namespace {

// OpenCV's SIFT keypoints and descriptors as its detectAndCompute gives them; where the CPU runs
// pnpba's kernels, the keypoints (sift_detection.h) and the descriptors (sift_descriptors.h, three
// quarters of the time) from one scale space.
void siftDetectAndDescribe(const OrbOptions& options, const cv::Mat& image, Features* f) {
  if (siftDetectionAvailable()) {
    siftDetectAndCompute(image, options.num_features, options.sift_contrast_threshold,
                         &f->keypoints, &f->descriptors);
    return;
  }
  const cv::Ptr<cv::SIFT> sift =
      cv::SIFT::create(options.num_features, 3, options.sift_contrast_threshold);
  if (!fastSiftDescriptorsAvailable()) {
    sift->detectAndCompute(image, cv::noArray(), f->keypoints, f->descriptors);
    return;
  }
  sift->detect(image, f->keypoints);  // an AVX-512 CPU: OpenCV detects, pnpba describes
  f->descriptors = siftDescriptors(image, f->keypoints);
}

// OpenCV's SIFT always doubles its input, and reports keypoints a quarter pixel right of and below
// where they are: it maps the doubled image back by halving coordinates, where its resize put
// doubled pixel j at j/2 - 1/4 (measured on rendered blobs: +0.25 px in x and y). The quarter is
// taken off here. For first octave 0 it is given the image halved by 2x2 means, which it doubles
// back, so its scale space starts at the image's own resolution with a quarter of the pixels to
// blur; half-image pixel x covers full-image pixels 2x and 2x + 1, so a keypoint it reports at x
// (x - 1/4 in truth) is at 2x in the image, one octave coarser than OpenCV says.
Features detectSift(const cv::Mat& image, const OrbOptions& options) {
  Features f;
  if (options.sift_first_octave == -1 ||
      std::min(image.cols, image.rows) < (8 << options.sift_first_octave)) {
    siftDetectAndDescribe(options, image, &f);
    for (cv::KeyPoint& k : f.keypoints) k.pt -= cv::Point2f(0.25f, 0.25f);
    return f;
  }
  // Octave o >= 0: SIFT (which doubles its input) on the image shrunk by 2^(o + 1), so that its
  // scale space starts at 2^-o of the image's resolution. A shrunk pixel u' covers full pixels
  // s u' .. s u' + s - 1 (s = 2^(o + 1)) and OpenCV's coordinates sit a quarter pixel off, so
  // a keypoint at u' lies at s (u' - 1/4) + (s - 1) / 2 = s u' + s / 4 - 1/2.
  const int s = 1 << (options.sift_first_octave + 1);
  cv::Mat shrunk;
  cv::Point2f scale(static_cast<float>(s), static_cast<float>(s));
  if (options.sift_octave_fraction == 1) {
    const cv::Rect whole(0, 0, image.cols - image.cols % s, image.rows - image.rows % s);
    cv::resize(image(whole), shrunk, cv::Size(whole.width / s, whole.height / s), 0, 0,
               cv::INTER_AREA);
  } else {
    // Shrunk by s / fraction, by area: shrunk pixel centres u' + 1/2 lie on full ones
    // (u' + 1/2) w / w' (w / w' per axis), so the keypoint at u' lies at (u' + 1/4) w / w' - 1/2,
    // as above with s = w / w'.
    const double by = s / options.sift_octave_fraction;
    const cv::Size size(std::max(1, static_cast<int>(std::lround(image.cols / by))),
                        std::max(1, static_cast<int>(std::lround(image.rows / by))));
    cv::resize(image, shrunk, size, 0, 0, cv::INTER_AREA);
    scale = {static_cast<float>(image.cols) / size.width,
             static_cast<float>(image.rows) / size.height};
  }
  siftDetectAndDescribe(options, shrunk, &f);
  const cv::Point2f offset(0.25f * scale.x - 0.5f, 0.25f * scale.y - 0.5f);
  for (cv::KeyPoint& k : f.keypoints) {
    k.pt = cv::Point2f(k.pt.x * scale.x, k.pt.y * scale.y) + offset;
    k.size *= 0.5f * (scale.x + scale.y);
    // Whole octaves only: a fraction of one (at most 2x finer) leaves the index, and the pixel
    // sigma read from it (keypointSigma), as the whole octaves give it.
    const int octave = static_cast<int8_t>(k.octave & 255) + options.sift_first_octave + 1;
    k.octave = (k.octave & ~255) | (octave & 255);
  }
  return f;
}

// ORB or AKAZE on the image as given.
Features detectAtOwnResolution(const cv::Mat& image, const OrbOptions& options) {
  Features f;
  if (options.detector == Detector::kAkaze) {
    // AKAZE has a response threshold, not a count: the strongest num_features are described.
    const cv::Ptr<cv::AKAZE> akaze = cv::AKAZE::create();
    akaze->detect(image, f.keypoints);
    cv::KeyPointsFilter::retainBest(f.keypoints, options.num_features);
    akaze->compute(image, f.keypoints, f.descriptors);
    return f;
  }
  // cv::ORB's defaults but for the chosen counts: the Harris score, as the textbook's
  // cv::ORB::create() ranks its keypoints; its levels as tasks of their own (orb_levels.h).
  return orbByLevel(image, options);
}

}  // namespace

Features detectOrb(const cv::Mat& image, const OrbOptions& options) {
  if (image.empty()) throw Error("image is empty");
  if (image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3)) {
    throw Error("image must be 8-bit grey or colour");
  }
  const std::string problem = options.validate();
  if (!problem.empty()) throw Error(problem);
  if (options.detector == Detector::kSift) return detectSift(image, options);
  const double pixels = static_cast<double>(image.cols) * image.rows;
  if (options.max_pixels == 0 || pixels <= options.max_pixels) {
    return detectAtOwnResolution(image, options);
  }
  // Shrunk by a whole factor s, the smallest that brings it to max_pixels at most, by s x s
  // means: OpenCV's area resampling at a whole factor is a few additions a pixel, where any
  // other ratio costs more than the ORB it spares (18.5 ms for a colour 1664 x 1248 image). The
  // last cols % s columns and rows % s rows are left out. Pixel j of the copy covers the image's
  // s j .. s j + s - 1, so a keypoint at u' lies at s u' + (s - 1) / 2 in the image's pixels.
  const int s = static_cast<int>(std::ceil(std::sqrt(pixels / options.max_pixels) - 1e-9));
  // A strip thinner than the factor has nothing to shrink.
  if (image.cols < s || image.rows < s) return detectAtOwnResolution(image, options);
  const cv::Rect whole(0, 0, image.cols - image.cols % s, image.rows - image.rows % s);
  cv::Mat shrunk;
  cv::resize(image(whole), shrunk, cv::Size(whole.width / s, whole.height / s), 0, 0,
             cv::INTER_AREA);
  Features f = detectAtOwnResolution(shrunk, options);
  f.pixel_scale = s;
  const float offset = 0.5f * static_cast<float>(s - 1);
  for (cv::KeyPoint& k : f.keypoints) {
    k.pt = cv::Point2f(k.pt.x * static_cast<float>(s) + offset,
                       k.pt.y * static_cast<float>(s) + offset);
    k.size *= static_cast<float>(s);
  }
  return f;
}

std::pair<Features, Features> detectOrbPair(const cv::Mat& image1, const cv::Mat& image2,
                                            const OrbOptions& options) {
  // The two images side by side on TBB's workers, each image's levels tasks of their own
  // (orb_levels.h) that either core takes. ORB's own threading is idle at this size; a worker
  // still spinning after the last pair's parallel loops takes work at once, where a new thread
  // waited for that core (fr1_desk's two images: 7.7-9.6 ms after a parallel loop, 6.9-7.4 on
  // TBB, medians of 100 pairs). SIFT's scale space runs in OpenCV's parallel loops, which are
  // TBB's too and nest in these: the sweep's SIFT retry (640 x 480, an AVX2 machine, medians of
  // 10) 80-84 ms for the two images one after the other, 73-78 side by side (two std::async
  // threads had crowded them instead).
  Features first, second;
  tbb::parallel_invoke([&] { first = detectOrb(image1, options); },
                       [&] { second = detectOrb(image2, options); });
  return {std::move(first), std::move(second)};
}

}  // namespace pnpba
