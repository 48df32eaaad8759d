#include "pnpba/features/orb_features.h"

#include <future>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "pnpba/core/error.h"

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
  return "";
}

Features detectOrb(const cv::Mat& image, const OrbOptions& options) {
  if (image.empty()) throw Error("image is empty");
  if (image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3)) {
    throw Error("image must be 8-bit grey or colour");
  }
  const std::string problem = options.validate();
  if (!problem.empty()) throw Error(problem);
  Features f;
  if (options.detector == Detector::kSift) {
    cv::SIFT::create(options.num_features)
        ->detectAndCompute(image, cv::noArray(), f.keypoints, f.descriptors);
    return f;
  }
  if (options.detector == Detector::kAkaze) {
    // AKAZE has a response threshold, not a count: the strongest num_features are described.
    const cv::Ptr<cv::AKAZE> akaze = cv::AKAZE::create();
    akaze->detect(image, f.keypoints);
    cv::KeyPointsFilter::retainBest(f.keypoints, options.num_features);
    akaze->compute(image, f.keypoints, f.descriptors);
    return f;
  }
  // cv::ORB's defaults but for the chosen counts; FAST score as the textbook uses.
  cv::Ptr<cv::ORB> orb =
      cv::ORB::create(options.num_features, options.scale_factor, options.levels, 31, 0, 2,
                      cv::ORB::HARRIS_SCORE, 31, options.fast_threshold);
  orb->detectAndCompute(image, cv::noArray(), f.keypoints, f.descriptors);
  return f;
}

std::pair<Features, Features> detectOrbPair(const cv::Mat& image1, const cv::Mat& image2,
                                            const OrbOptions& options) {
  // OpenCV's own threading is idle at this size; one image per core is what pays.
  auto second = std::async(std::launch::async, [&] { return detectOrb(image2, options); });
  Features first = detectOrb(image1, options);
  return {std::move(first), second.get()};
}

}  // namespace pnpba
