#include "pipeline/core/jpeg_decode.h"

#include <csetjmp>
#include <cstdio>
#include <cstring>

#include <jpeglib.h>

namespace fresco {
namespace {

struct ErrorManager {
  jpeg_error_mgr pub;
  std::jmp_buf jump;
};

[[noreturn]] void JumpOnError(j_common_ptr info) {
  std::longjmp(reinterpret_cast<ErrorManager*>(info->err)->jump, 1);
}
// Warnings (e.g. corrupt data recovered from) are ignored, as OpenCV ignores them.
void IgnoreMessage(j_common_ptr) {}

// What the EXIF APP1 segment says of the orientation: 1 (upright, or no tag in a well-formed
// first directory), the tag's value, or 0 when the segment cannot be read.
int ExifOrientation(const JOCTET* data, unsigned size) {
  if (size < 14 || std::memcmp(data, "Exif\0\0", 6) != 0) return 0;
  const JOCTET* tiff = data + 6;
  const unsigned n = size - 6;
  const bool little = tiff[0] == 'I' && tiff[1] == 'I';
  if (!little && !(tiff[0] == 'M' && tiff[1] == 'M')) return 0;
  const auto u16 = [&](unsigned at) {
    return little ? tiff[at] | tiff[at + 1] << 8 : tiff[at] << 8 | tiff[at + 1];
  };
  const auto u32 = [&](unsigned at) {
    return little ? static_cast<unsigned>(u16(at)) | static_cast<unsigned>(u16(at + 2)) << 16
                  : static_cast<unsigned>(u16(at)) << 16 | static_cast<unsigned>(u16(at + 2));
  };
  const unsigned ifd = u32(4);
  if (ifd > n - 2) return 0;
  const unsigned entries = u16(ifd);
  if (entries > (n - ifd - 2) / 12) return 0;
  for (unsigned e = 0; e < entries; ++e) {
    const unsigned at = ifd + 2 + 12 * e;
    if (u16(at) == 0x0112) return u16(at + 2) == 3 ? u16(at + 8) : 0;  // SHORT
  }
  return 1;
}

}  // namespace

bool DecodeJpegBgr(const std::string& bytes, cv::Mat* image) {
  return DecodeJpegBgr(bytes.data(), bytes.size(), image);
}

bool DecodeJpegBgr(const void* data, size_t size, cv::Mat* image) {
  image->release();
  const auto* bytes = static_cast<const unsigned char*>(data);
  if (size < 3 || bytes[0] != 0xff || bytes[1] != 0xd8) return false;
  jpeg_decompress_struct info;
  ErrorManager error;
  info.err = jpeg_std_error(&error.pub);
  error.pub.error_exit = JumpOnError;
  error.pub.output_message = IgnoreMessage;
  // Nothing with a destructor is created between here and the last jpeg_* call: a longjmp
  // back here skips no destructor. `image` belongs to the caller.
  if (setjmp(error.jump)) {
    jpeg_destroy_decompress(&info);
    image->release();
    return false;
  }
  jpeg_create_decompress(&info);
  jpeg_mem_src(&info, bytes, static_cast<unsigned long>(size));
  jpeg_save_markers(&info, JPEG_APP0 + 1, 0xffff);
  jpeg_read_header(&info, TRUE);
  for (jpeg_saved_marker_ptr m = info.marker_list; m; m = m->next) {
    if (m->marker == JPEG_APP0 + 1 && m->data_length >= 6 &&
        std::memcmp(m->data, "Exif\0\0", 6) == 0 && ExifOrientation(m->data, m->data_length) != 1) {
      jpeg_destroy_decompress(&info);
      return false;  // rotated or unreadable: cv::imdecode applies what OpenCV applies
    }
  }
  if (info.num_components != 1 && info.num_components != 3) {
    jpeg_destroy_decompress(&info);
    return false;
  }
  // Larger than OpenCV decodes (CV_IO_MAX_IMAGE_PIXELS): its error, not an allocation here.
  if (static_cast<double>(info.image_width) * info.image_height > double{1 << 30}) {
    jpeg_destroy_decompress(&info);
    return false;
  }
  info.out_color_space = JCS_EXT_BGR;
  jpeg_start_decompress(&info);
  image->create(static_cast<int>(info.output_height), static_cast<int>(info.output_width), CV_8UC3);
  while (info.output_scanline < info.output_height) {
    JSAMPROW row = image->ptr<JSAMPLE>(static_cast<int>(info.output_scanline));
    jpeg_read_scanlines(&info, &row, 1);
  }
  jpeg_finish_decompress(&info);
  jpeg_destroy_decompress(&info);
  return true;
}

}  // namespace fresco
