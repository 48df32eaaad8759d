#include "pnpba/pipeline/image_files.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>  // the flags; the codecs come through pnpba::imageio
#include <opencv2/imgproc.hpp>
#include <vector>

#include "pnpba/core/error.h"
#include "pnpba/imageio/image_codec.h"

namespace pnpba {

namespace {

// Silences the process's stderr while alive: libpng and libjpeg print their own bare errors
// ("libpng error: Read Error") before OpenCV returns an empty image, and the one line the user
// should see is ours, naming the file.
class QuietStderr {
 public:
  QuietStderr() : saved_(::dup(STDERR_FILENO)) {
    const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_ >= 0 && null >= 0) ::dup2(null, STDERR_FILENO);
    if (null >= 0) ::close(null);
  }
  ~QuietStderr() {
    if (saved_ >= 0) {
      ::dup2(saved_, STDERR_FILENO);
      ::close(saved_);
    }
  }

 private:
  int saved_;
};

cv::Mat readImage(const std::string& path, int flags) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw Error(path + ": cannot open file");
  if (std::filesystem::is_directory(path, ec)) throw Error(path + ": is a folder, not an image");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open file (" + std::strerror(errno) + ")");
  const std::vector<uchar> bytes = readAllBytes(in);
  if (in.fail()) throw Error(path + ": cannot read file (" + std::strerror(errno) + ")");
  if (bytes.empty()) throw Error(path + ": empty file, not an image");
  cv::Mat image;
  try {
    const QuietStderr quiet;
    image = pnpba::decodeImage(bytes, flags);
  } catch (const cv::Exception&) {
  }
  if (image.empty()) throw Error(path + ": not an image OpenCV can decode");
  return image;
}

}  // namespace

cv::Mat readColourImage(const std::string& path) {
  cv::Mat image = readImage(path, cv::IMREAD_UNCHANGED);
  if (image.depth() != CV_8U) {
    throw Error(path + ": expected an 8-bit colour image, got " +
                std::to_string(image.elemSize1() * 8) + "-bit (a depth image?)");
  }
  if (image.channels() == 4) {  // drop the alpha channel
    cv::Mat bgr;
    cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
    return bgr;
  }
  return image;
}

cv::Mat readDepthImage(const std::string& path) { return readImage(path, cv::IMREAD_UNCHANGED); }

}  // namespace pnpba
