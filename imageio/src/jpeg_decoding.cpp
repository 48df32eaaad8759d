#include "jpeg_decoding.h"

#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <vector>

// After <cstdio>: jpeglib.h needs size_t and FILE declared before it.
#include <jpeglib.h>

namespace pnpba {

namespace {

// cv::ImreadModes values (opencv2/imgcodecs.hpp is not this module's).
constexpr int kUnchanged = -1, kGrayscale = 0, kColor = 1, kAnyDepth = 2;

// Walks the markers before the scan: false where an APP1 segment holds EXIF (whose orientation
// OpenCV applies under every flag but IMREAD_UNCHANGED) or the stream is not a JPEG.
bool plainJpeg(const unsigned char* bytes, size_t size, bool exif_matters) {
  if (size < 4 || bytes[0] != 0xFF || bytes[1] != 0xD8) return false;
  size_t at = 2;
  while (at + 4 <= size) {
    if (bytes[at] != 0xFF) return false;
    const unsigned char marker = bytes[at + 1];
    if (marker == 0xDA) return true;  // start of scan
    const size_t length = (size_t{bytes[at + 2]} << 8) | bytes[at + 3];
    if (marker == 0xE1 && exif_matters && length >= 8 && at + 10 <= size &&
        std::memcmp(bytes + at + 4, "Exif\0\0", 6) == 0) {
      return false;
    }
    at += 2 + length;
  }
  return false;
}

struct QuietErrors {
  jpeg_error_mgr manager;
  std::jmp_buf jump;
};

[[noreturn]] void jumpOnError(j_common_ptr info) {
  std::longjmp(reinterpret_cast<QuietErrors*>(info->err)->jump, 1);
}
void countWithoutPrinting(j_common_ptr info, int level) {
  if (level < 0) ++info->err->num_warnings;  // a warning: damaged data libjpeg fills in
}

// No object with a destructor lives between the setjmp and the end of decoding.
bool decodeWith(jpeg_decompress_struct* info, QuietErrors* errors, const unsigned char* bytes,
                size_t size, int flags, cv::Mat* image, std::vector<unsigned char>* row) {
  if (setjmp(errors->jump) != 0) return false;
  jpeg_mem_src(info, bytes, static_cast<unsigned long>(size));
  jpeg_read_header(info, TRUE);
  // Motion-JPEG frames without Huffman tables, and CMYK, OpenCV treats in its own ways.
  if (info->num_components != 1 && info->num_components != 3) return false;
  if (info->ac_huff_tbl_ptrs[0] == nullptr && info->ac_huff_tbl_ptrs[1] == nullptr &&
      info->dc_huff_tbl_ptrs[0] == nullptr && info->dc_huff_tbl_ptrs[1] == nullptr) {
    return false;
  }
  const int file_channels = info->num_components > 1 ? 3 : 1;
  const int channels = flags == kUnchanged ? file_channels : ((flags & kColor) != 0 ? 3 : 1);
  info->out_color_space = channels == 3 ? JCS_RGB : JCS_GRAYSCALE;
  info->out_color_components = channels;
  jpeg_start_decompress(info);
  const JDIMENSION width = info->output_width, height = info->output_height;
  if (width == 0 || height == 0 || width > (1u << 20) || height > (1u << 20) ||
      static_cast<unsigned long long>(width) * height > (1ull << 30) ||
      info->output_components != channels) {
    return false;
  }
  image->create(static_cast<int>(height), static_cast<int>(width), CV_8UC(channels));
  row->resize(static_cast<size_t>(width) * channels);
  for (JDIMENSION y = 0; y < height; ++y) {
    unsigned char* line = row->data();
    jpeg_read_scanlines(info, &line, 1);
    unsigned char* out = image->ptr(static_cast<int>(y));
    if (channels == 1) {
      std::memcpy(out, line, width);
      continue;
    }
    for (JDIMENSION x = 0; x < width; ++x) {  // RGB to BGR
      out[3 * x] = line[3 * x + 2];
      out[3 * x + 1] = line[3 * x + 1];
      out[3 * x + 2] = line[3 * x];
    }
  }
  jpeg_finish_decompress(info);
  return errors->manager.num_warnings == 0;
}

}  // namespace

bool decodeJpeg(const unsigned char* bytes, size_t size, int flags, cv::Mat* out) {
  if (flags != kUnchanged && flags != kGrayscale && flags != kColor &&
      flags != (kAnyDepth | kGrayscale) && flags != (kAnyDepth | kColor)) {
    return false;
  }
  if (bytes == nullptr || !plainJpeg(bytes, size, flags != kUnchanged)) return false;
  jpeg_decompress_struct info;
  QuietErrors errors;
  info.err = jpeg_std_error(&errors.manager);
  errors.manager.error_exit = jumpOnError;
  errors.manager.emit_message = countWithoutPrinting;
  jpeg_create_decompress(&info);
  cv::Mat image;
  std::vector<unsigned char> row;
  const bool ok = decodeWith(&info, &errors, bytes, size, flags, &image, &row);
  jpeg_destroy_decompress(&info);
  if (!ok) return false;
  *out = image;
  return true;
}

}  // namespace pnpba
