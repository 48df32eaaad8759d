#include "pnpba/pipeline/image_files.h"

#include <fcntl.h>
#include <oneapi/tbb/parallel_for.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <mutex>
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

void checkIsAFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw Error(path + ": cannot open file");
  if (std::filesystem::is_directory(path, ec)) throw Error(path + ": is a folder, not an image");
}

cv::Mat readImage(const std::string& path, int flags) {
  checkIsAFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open file (" + std::strerror(errno) + ")");
  const std::vector<uchar> bytes = readAllBytes(in);
  if (in.fail()) throw Error(path + ": cannot read file (" + std::strerror(errno) + ")");
  if (bytes.empty()) throw Error(path + ": empty file, not an image");
  cv::Mat image;
  if (decodeImageWithoutPlugin(bytes, flags, &image)) return image;
  // OpenCV's codecs, one file at a time: the silenced stderr is the whole process's.
  static std::mutex codecs;
  const std::lock_guard<std::mutex> one_at_a_time(codecs);
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

TwoViewImages readTwoViewImages(const std::string& image1, const std::string& image2,
                                const std::string& depth1, const std::string& depth2) {
  // A missing file or a folder is reported before any file is read: a later argument that is a
  // pipe with nothing written to it would otherwise hold up the error.
  for (const std::string* path : {&image1, &image2, &depth1}) checkIsAFile(*path);
  if (!depth2.empty()) checkIsAFile(depth2);
  TwoViewImages out;
  std::exception_ptr failed[4];
  auto read = [&](int k) {
    try {
      switch (k) {
        case 0:
          out.image1 = readColourImage(image1);
          break;
        case 1:
          out.image2 = readColourImage(image2);
          break;
        case 2:
          out.depth1 = readDepthImage(depth1);
          break;
        default:
          if (!depth2.empty()) out.depth2 = readDepthImage(depth2);
      }
    } catch (...) {
      failed[k] = std::current_exception();
    }
  };
  // On TBB's workers, which the estimate then finds running rather than starting them itself.
  tbb::parallel_for(0, 4, read);
  for (const std::exception_ptr& e : failed) {
    if (e) std::rethrow_exception(e);
  }
  return out;
}

}  // namespace pnpba
