#include "pnpba/imageio/image_codec.h"

#include <fstream>
#include <iterator>

#include "imgcodecs_plugin_api.h"
#include "pnpba/core/plugin.h"

namespace pnpba {

cv::Mat decodeImage(const std::vector<unsigned char>& bytes, int flags) {
  static auto* decode = pluginFunction<ImgcodecsDecode>(kImgcodecsPlugin, "pnpba_imgcodecs_decode");
  cv::Mat image;
  if (!bytes.empty()) decode(bytes.data(), bytes.size(), flags, &image);
  return image;
}

bool encodeImage(const std::string& extension, const cv::Mat& image,
                 std::vector<unsigned char>* bytes, const std::vector<int>& params) {
  static auto* encode = pluginFunction<ImgcodecsEncode>(kImgcodecsPlugin, "pnpba_imgcodecs_encode");
  return encode(extension.c_str(), &image, &params, bytes);
}

cv::Mat loadImage(const std::string& path, int flags) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return cv::Mat();
  const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)),
                                         std::istreambuf_iterator<char>());
  return decodeImage(bytes, flags);
}

}  // namespace pnpba
