#include "png_decoding.h"

#include <png.h>

#include <cstdint>
#include <cstring>
#include <vector>

namespace pnpba {

namespace {

// cv::ImreadModes values (opencv2/imgcodecs.hpp, not included: this module does not link it).
constexpr int kUnchanged = -1, kGrayscale = 0, kColor = 1, kAnyDepth = 2;

uint32_t bigEndian32(const unsigned char* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | p[3];
}

// Walks the chunks before the image data: false for an animation (acTL) or EXIF (eXIf), which
// OpenCV treats specially, and for a chunk list that runs off the end.
bool plainPng(const unsigned char* bytes, size_t size) {
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (size < 8 || std::memcmp(bytes, kSignature, 8) != 0) return false;
  size_t at = 8;
  while (at + 8 <= size) {
    const uint64_t length = bigEndian32(bytes + at);
    const unsigned char* type = bytes + at + 4;
    if (std::memcmp(type, "acTL", 4) == 0 || std::memcmp(type, "eXIf", 4) == 0) return false;
    if (std::memcmp(type, "IDAT", 4) == 0) return true;
    at += 12 + length;
  }
  return false;
}

struct Source {
  const unsigned char* bytes;
  size_t size, at;
};

void readFromSource(png_structp png, png_bytep into, png_size_t count) {
  auto* source = static_cast<Source*>(png_get_io_ptr(png));
  if (count > source->size - source->at) png_error(png, "truncated");
  std::memcpy(into, source->bytes + source->at, count);
  source->at += count;
}

// Quiet: a PNG libpng cannot decode goes to OpenCV, which reports it as it always has.
void ignoreWarning(png_structp, png_const_charp) {}
[[noreturn]] void quietError(png_structp png, png_const_charp) { png_longjmp(png, 1); }

// What OpenCV's decoder reports as the file's own type: channels from the colour type (3 or 4
// for RGB and palette, 4 where transparency is given, 1 for grey), 16-bit where the file is.
int fileType(png_structp png, png_infop info, int bit_depth, int colour_type) {
  int channels = 1;
  if (colour_type == PNG_COLOR_TYPE_RGB || colour_type == PNG_COLOR_TYPE_PALETTE) {
    png_bytep trans = nullptr;
    int num_trans = 0;
    png_color_16p trans_values = nullptr;
    png_get_tRNS(png, info, &trans, &num_trans, &trans_values);
    channels = num_trans > 0 ? 4 : 3;
  } else if (colour_type == PNG_COLOR_TYPE_GRAY_ALPHA || colour_type == PNG_COLOR_TYPE_RGB_ALPHA) {
    channels = 4;
  }
  return CV_MAKETYPE(bit_depth == 16 ? CV_16U : CV_8U, channels);
}

// What cv::imdecode makes of the file's type under `flags` (loadsave.cpp).
int requestedType(int file_type, int flags) {
  if (flags == kUnchanged) return file_type;
  const int depth = (flags & kAnyDepth) != 0 ? CV_MAT_DEPTH(file_type) : CV_8U;
  return CV_MAKETYPE(depth, (flags & kColor) != 0 ? 3 : 1);
}

bool littleEndian() {
  const uint16_t one = 1;
  unsigned char first;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

// libpng reports errors by longjmp: no object with a destructor is created between the setjmp
// and the end of decoding, and what changes after it is volatile or lives outside.
bool decodeWith(png_structp png, png_infop info, png_infop end, Source* source, int flags,
                cv::Mat* image, std::vector<png_bytep>* rows) {
  if (setjmp(png_jmpbuf(png)) != 0) return false;
  png_set_read_fn(png, source, readFromSource);
  png_read_info(png, info);
  png_uint_32 width = 0, height = 0;
  int bit_depth = 0, colour_type = 0;
  png_get_IHDR(png, info, &width, &height, &bit_depth, &colour_type, nullptr, nullptr, nullptr);
  // Beyond OpenCV's own size limits (CV_IO_MAX_IMAGE_*) it decides.
  if (width == 0 || height == 0 || width > (1u << 20) || height > (1u << 20) ||
      uint64_t{width} * height > (uint64_t{1} << 30)) {
    return false;
  }
  const int type = requestedType(fileType(png, info, bit_depth, colour_type), flags);
  const int channels = CV_MAT_CN(type);
  // The transforms OpenCV's PngDecoder::readData asks for, in its order.
  if (CV_MAT_DEPTH(type) == CV_8U && bit_depth == 16) {
    png_set_strip_16(png);
  } else if (littleEndian()) {
    png_set_swap(png);
  }
  if (channels < 4) {
    png_set_strip_alpha(png);
  } else {
    png_set_tRNS_to_alpha(png);
  }
  if (colour_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if ((colour_type & PNG_COLOR_MASK_COLOR) == 0 && bit_depth < 8) {
    png_set_expand_gray_1_2_4_to_8(png);
  }
  if ((colour_type & PNG_COLOR_MASK_COLOR) != 0 && channels > 1) {
    png_set_bgr(png);
  } else if (channels > 1) {
    png_set_gray_to_rgb(png);
  } else {
    png_set_rgb_to_gray(png, 1, 0.299, 0.587);
  }
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  image->create(static_cast<int>(height), static_cast<int>(width), type);
  // A transform that left rows of another size than the Mat's would write past them.
  if (png_get_rowbytes(png, info) != image->cols * image->elemSize()) return false;
  rows->resize(height);
  for (png_uint_32 y = 0; y < height; ++y) (*rows)[y] = image->ptr(static_cast<int>(y));
  png_read_image(png, rows->data());
  png_read_end(png, end);
  return true;
}

}  // namespace

bool decodePng(const unsigned char* bytes, size_t size, int flags, cv::Mat* out) {
  if (flags != kUnchanged && flags != kGrayscale && flags != kColor &&
      flags != (kAnyDepth | kGrayscale) && flags != (kAnyDepth | kColor)) {
    return false;
  }
  if (bytes == nullptr || !plainPng(bytes, size)) return false;
  png_structp png =
      png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, quietError, ignoreWarning);
  if (png == nullptr) return false;
  png_infop info = png_create_info_struct(png);
  png_infop end = png_create_info_struct(png);
  Source source{bytes, size, 0};
  cv::Mat image;
  std::vector<png_bytep> rows;
  const bool ok = info != nullptr && end != nullptr &&
                  decodeWith(png, info, end, &source, flags, &image, &rows);
  png_destroy_read_struct(&png, &info, &end);
  if (!ok) return false;
  *out = image;
  return true;
}

}  // namespace pnpba
