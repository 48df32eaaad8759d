// The images the SIFT kernels are compared with OpenCV on: shared real frames (the textbook's
// pair and the first three of each folder asked for) each as SIFT sees it in the pipeline: in
// colour at ORB's feature count, in grey at half the contrast threshold, and shrunk as the SIFT
// retry shrinks it.
#pragma once

#include <algorithm>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

namespace pnpba::testing {

struct SiftTestImage {
  std::string what;  // the file and the variant, for failure messages
  cv::Mat image;
  int features;
  double contrast;
};

inline std::string sharedImage(const std::string& relative) {
  return std::string(PNPBA_SHARED_DATA) + "/" + relative;
}

// `folders` relative to the shared data (e.g. "tum_fr1_desk/rgb"); empty where the shared data
// is absent.
inline std::vector<SiftTestImage> sharedSiftTestImages(const std::vector<std::string>& folders) {
  std::vector<std::string> names = {"slambook_ch7/1.png", "slambook_ch7/2.png"};
  if (!std::filesystem::exists(sharedImage(names[0]))) return {};
  for (const std::string& folder : folders) {
    const std::string path = sharedImage(folder);
    if (!std::filesystem::exists(path)) continue;
    std::vector<std::string> files;
    for (const auto& entry : std::filesystem::directory_iterator(path)) {
      files.push_back(entry.path().filename().string());
    }
    std::sort(files.begin(), files.end());
    files.resize(std::min<size_t>(files.size(), 3));
    for (const std::string& file : files) names.push_back(folder + "/" + file);
  }
  std::vector<SiftTestImage> images;
  for (const std::string& name : names) {
    const cv::Mat colour = cv::imread(sharedImage(name), cv::IMREAD_COLOR);
    if (colour.empty()) continue;  // the caller counts what it got
    cv::Mat grey, shrunk;
    cv::cvtColor(colour, grey, cv::COLOR_BGR2GRAY);
    // The SIFT retry's input: the image shrunk by 2 / 0.85, by area.
    cv::resize(colour, shrunk, cv::Size(272, 204), 0, 0, cv::INTER_AREA);
    images.push_back({name + " (colour)", colour, 1500, 0.04});
    images.push_back({name + " (grey, low contrast)", grey, 3000, 0.02});
    images.push_back({name + " (shrunk)", shrunk, 3000, 0.02});
  }
  return images;
}

}  // namespace pnpba::testing
