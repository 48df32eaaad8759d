// The imgcodecs plugin: cv::imdecode and cv::imencode behind the interface of
// imageio/src/imgcodecs_plugin_api.h, in a module opened only when an image is decoded or
// encoded.
#include <opencv2/imgcodecs.hpp>

#include "../src/imgcodecs_plugin_api.h"

#define PNPBA_PLUGIN_EXPORT extern "C" __attribute__((visibility("default")))

PNPBA_PLUGIN_EXPORT void pnpba_imgcodecs_decode(const unsigned char* data, size_t size, int flags,
                                                cv::Mat* image) {
  static_assert(std::is_same_v<decltype(pnpba_imgcodecs_decode), pnpba::ImgcodecsDecode>);
  try {
    *image = cv::imdecode(
        cv::Mat(1, static_cast<int>(size), CV_8UC1, const_cast<unsigned char*>(data)), flags);
  } catch (const cv::Exception&) {
    image->release();
  }
}

PNPBA_PLUGIN_EXPORT bool pnpba_imgcodecs_encode(const char* extension, const cv::Mat* image,
                                                const std::vector<int>* params,
                                                std::vector<unsigned char>* bytes) {
  static_assert(std::is_same_v<decltype(pnpba_imgcodecs_encode), pnpba::ImgcodecsEncode>);
  try {
    return cv::imencode(extension, *image, *bytes, *params);
  } catch (const cv::Exception&) {
    return false;
  }
}
