// ORB keypoints and descriptors (cv::ORB), for one image or for two images concurrently.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

namespace pnpba {

// The keypoint detector and descriptor. ORB (binary, Hamming-matched) is the default; SIFT
// (cv::SIFT, float descriptors matched by L2) and AKAZE (cv::AKAZE, binary MLDB descriptors
// matched by Hamming distance, at most num_features of the strongest) are there to be measured
// against it at large motions (docs/two_view.md "Front end at large motion").
enum class Detector { kOrb, kSift, kAkaze };
const char* toString(Detector detector);
Detector parseDetector(const std::string& name);  // "orb", "sift", "akaze"; throws Error

struct OrbOptions {
  Detector detector = Detector::kOrb;
  // Defaults chosen by measured accuracy (docs/two_view.md "What each choice bought"): 1500
  // features on 4 levels beat 1000 on 8 on real sequences; two views of one scene need little scale
  // range.
  int num_features = 1500;
  float scale_factor = 1.2f;
  int levels = 4;
  int fast_threshold = 20;
  // SIFT only. first octave -1 is Lowe's and OpenCV's (the image doubled first); 0 starts the
  // scale space at the image's own resolution (VLFeat's default): about a quarter of the work,
  // without the finest blobs; each octave more (up to 4) starts it at half the last resolution.
  // Contrast threshold as OpenCV's (divided by its 3 layers).
  int sift_first_octave = -1;
  // SIFT only, with sift_first_octave >= 0: the scale space starts at this fraction (0.5, 1] of
  // the first octave's resolution, the image resampled by area instead of halved alone, so that
  // an image between two octaves (832 x 624) costs what 640 x 480 does.
  double sift_octave_fraction = 1.0;
  double sift_contrast_threshold = 0.04;
  // ORB and AKAZE: an image of more pixels than this is detected on a copy shrunk by the
  // smallest whole factor that brings it within (2 x 2 means for 1920 x 1080, 3 x 3 for 3840 x
  // 2160; never below 640 x 480's pixel count), its keypoints mapped back to the image's own
  // pixels (Features::pixel_scale). ORB's time grows with the pixels (30 ms a pair at 1920 x
  // 1080, 12 on the halved copies), where the rest of the pipeline already works at 640 x 480's
  // size; the rendered sweep at 1920 x 1080 kept every answer (rich 36 / 0 / 0, poor 33 -> 34
  // within 2 deg / 5 cm) at about twice the error of the features' poses (rich median 0.02 ->
  // 0.05 deg; docs/benchmarks.md, "ORB on a whole-factor copy of large images").
  // 0: always at the image's own resolution.
  int max_pixels = 1280 * 960;
  std::string validate() const;  // empty when valid
};

// Every field equal: the same options find the same features in the same image (a field added
// to OrbOptions is compared there too).
bool operator==(const OrbOptions& a, const OrbOptions& b);
inline bool operator!=(const OrbOptions& a, const OrbOptions& b) { return !(a == b); }

struct Features {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;  // one row per keypoint: 32 bytes (ORB), 128 floats (SIFT), 61 bytes (AKAZE)
  // The image's pixels per pixel of the image the keypoints were found on: 1, or more where it
  // was shrunk for OrbOptions::max_pixels. A keypoint's position is that much less certain.
  double pixel_scale = 1.0;
};

// Accepts 8-bit grey or BGR images; throws Error for an empty or other image.
Features detectOrb(const cv::Mat& image, const OrbOptions& options);
// Both images at once on two threads.
std::pair<Features, Features> detectOrbPair(const cv::Mat& image1, const cv::Mat& image2,
                                            const OrbOptions& options);

}  // namespace pnpba
