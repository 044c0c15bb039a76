#include "pipeline/core/png_encode.h"

#include <csetjmp>
#include <string>

#include <png.h>

namespace fresco {
namespace {

void AppendToVector(png_structp png_ptr, png_bytep data, png_size_t length) {
  auto* out = static_cast<std::vector<uint8_t>*>(png_get_io_ptr(png_ptr));
  out->insert(out->end(), data, data + length);
}

void FlushNothing(png_structp) {}

// libpng reports errors by longjmp: this function holds no object with a destructor
// between setjmp and the calls that may jump back to it.
bool EncodeRows(png_structp png_ptr, png_infop info_ptr, const cv::Mat& image,
                std::vector<uint8_t>* png) {
  if (setjmp(png_jmpbuf(png_ptr))) return false;
  png_set_write_fn(png_ptr, png, &AppendToVector, &FlushNothing);
  png_set_filter(png_ptr, PNG_FILTER_TYPE_BASE, PNG_FILTER_UP);
  png_set_compression_level(png_ptr, 6);
  const bool colour = image.channels() == 3;
  png_set_IHDR(png_ptr, info_ptr, static_cast<png_uint_32>(image.cols),
               static_cast<png_uint_32>(image.rows), 8,
               colour ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_BASE, PNG_FILTER_TYPE_BASE);
  png_write_info(png_ptr, info_ptr);
  if (colour) png_set_bgr(png_ptr);
  for (int r = 0; r < image.rows; ++r)
    png_write_row(png_ptr, const_cast<png_bytep>(image.ptr<png_byte>(r)));
  png_write_end(png_ptr, info_ptr);
  return true;
}

}  // namespace

Status EncodeFastDecodingPng(const cv::Mat& image, std::vector<uint8_t>* png) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3))
    return Status::Internal("PNG encoding needs a non-empty 8-bit grey or BGR image, got type " +
                            std::to_string(image.type()) + " of " + std::to_string(image.cols) +
                            "x" + std::to_string(image.rows));
  png_structp png_ptr = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info_ptr = png_ptr ? png_create_info_struct(png_ptr) : nullptr;
  if (!info_ptr) {
    png_destroy_write_struct(&png_ptr, nullptr);
    return Status::Internal("PNG encoding: libpng could not start");
  }
  png->clear();
  png->reserve(image.total() * image.elemSize() / 4);
  const bool ok = EncodeRows(png_ptr, info_ptr, image, png);
  png_destroy_write_struct(&png_ptr, &info_ptr);
  if (!ok) return Status::Internal("PNG encoding failed in libpng");
  return Status::Ok();
}

}  // namespace fresco
