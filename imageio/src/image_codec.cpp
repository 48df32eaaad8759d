#include "pnpba/imageio/image_codec.h"

#include <fstream>
#include <iterator>

#include "imgcodecs_plugin_api.h"
#include "jpeg_decoding.h"
#include "png_decoding.h"
#include "pnpba/core/plugin.h"

namespace pnpba {

bool decodeImageWithoutPlugin(const std::vector<unsigned char>& bytes, int flags, cv::Mat* image) {
  return decodePng(bytes.data(), bytes.size(), flags, image) ||
         decodeJpeg(bytes.data(), bytes.size(), flags, image);
}

cv::Mat decodeImage(const std::vector<unsigned char>& bytes, int flags) {
  cv::Mat image;
  // A PNG or JPEG (RGB-D datasets' colour and depth) without loading OpenCV's codecs.
  if (decodeImageWithoutPlugin(bytes, flags, &image)) return image;
  static auto* decode = pluginFunction<ImgcodecsDecode>(kImgcodecsPlugin, "pnpba_imgcodecs_decode");
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
  const std::vector<unsigned char> bytes = readAllBytes(in);
  if (in.fail()) return cv::Mat();
  return decodeImage(bytes, flags);
}

std::vector<unsigned char> readAllBytes(std::istream& in) {
  // A byte at a time through istreambuf_iterator cost 0.5-1 ms per 640 x 480 PNG.
  const std::istream::pos_type start = in.tellg();
  if (start != std::istream::pos_type(-1) && in.seekg(0, std::ios::end)) {
    const std::streamoff size = in.tellg() - start;
    in.seekg(start);
    if (size >= 0 && in) {
      std::vector<unsigned char> bytes(static_cast<size_t>(size));
      in.read(reinterpret_cast<char*>(bytes.data()), size);
      return bytes;
    }
  }
  in.clear();
  return std::vector<unsigned char>(std::istreambuf_iterator<char>(in),
                                    std::istreambuf_iterator<char>());
}

}  // namespace pnpba
