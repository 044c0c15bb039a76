#include "pipeline/core/image_codecs.h"

#include <csetjmp>
#include <mutex>

#include <png.h>
#include <zlib.h>

#include <opencv2/imgcodecs.hpp>  // the IMREAD_* flags only

#include "pipeline/core/fresco_module.h"
#include "pipeline/core/jpeg_decode.h"

namespace fresco {
namespace {

struct CodecsModule {
  EncodeImageFunction encode = nullptr;
  DecodeImageFunction decode = nullptr;
  std::string error;
};

// The codecs module, loaded once.
const CodecsModule& Codecs() {
  static std::once_flag once;
  static CodecsModule module;
  std::call_once(once, [] {
    module.encode = reinterpret_cast<EncodeImageFunction>(
        LoadModuleSymbol(FRESCO_CODECS_MODULE_FROM_BINDIR, FRESCO_CODECS_MODULE_BUILD_PATH,
                         kEncodeImageSymbol, &module.error));
    module.decode = reinterpret_cast<DecodeImageFunction>(
        LoadModuleSymbol(FRESCO_CODECS_MODULE_FROM_BINDIR, FRESCO_CODECS_MODULE_BUILD_PATH,
                         kDecodeImageSymbol, &module.error));
  });
  return module;
}

std::string ModuleMissing(const CodecsModule& module) {
  return "Fresco's image codecs module did not load (" + module.error + ")";
}

void AppendBytes(png_structp png, png_bytep data, size_t size) {
  auto* bytes = static_cast<std::vector<uchar>*>(png_get_io_ptr(png));
  bytes->insert(bytes->end(), data, data + size);
}
void FlushNothing(png_structp) {}

// cv::imencode(".png") of 8- or 16-bit images of 1, 3 or 4 channels without parameters, as
// OpenCV 4.6 writes them (grfmt_png.cpp): every row filtered with "Sub", zlib level 1 with
// the RLE strategy, BGR(A) stored as RGB(A), 16-bit samples big-endian.
bool EncodePngAsOpenCV(const cv::Mat& image, std::vector<uchar>* bytes) {
  bytes->clear();
  const int channels = image.channels();
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  std::vector<png_bytep> rows(static_cast<size_t>(image.rows));
  for (int y = 0; y < image.rows; ++y) rows[static_cast<size_t>(y)] = image.data + y * image.step;
  // Nothing with a destructor is created between here and the last png_* call.
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    bytes->clear();
    return false;
  }
  png_set_write_fn(png, bytes, AppendBytes, FlushNothing);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_compression_level(png, Z_BEST_SPEED);
  png_set_compression_strategy(png, Z_RLE);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.cols),
               static_cast<png_uint_32>(image.rows), image.depth() == CV_8U ? 8 : 16,
               channels == 1   ? PNG_COLOR_TYPE_GRAY
               : channels == 3 ? PNG_COLOR_TYPE_RGB
                               : PNG_COLOR_TYPE_RGBA,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_set_bgr(png);
  png_set_swap(png);  // 16-bit samples to big-endian (this is a little-endian build)
  png_write_image(png, rows.data());
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

bool IsPng(const std::string& ext) {
  return ext.size() == 4 && ext[0] == '.' && (ext[1] | 0x20) == 'p' && (ext[2] | 0x20) == 'n' &&
         (ext[3] | 0x20) == 'g';
}

}  // namespace

bool EncodeImageBytes(const std::string& ext, const cv::Mat& image, std::vector<uchar>* bytes,
                      std::string* error) {
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "png_set_swap above");
  const int channels = image.channels();
  if (IsPng(ext) && !image.empty() && image.dims == 2 &&
      (image.depth() == CV_8U || image.depth() == CV_16U) &&
      (channels == 1 || channels == 3 || channels == 4)) {
    if (EncodePngAsOpenCV(image, bytes)) return true;
    if (error) error->clear();
    return false;
  }
  const CodecsModule& module = Codecs();
  std::string why;
  if (module.encode && module.encode(ext, image, bytes, &why)) return true;
  if (error) *error = module.encode ? why : ModuleMissing(module);
  return false;
}

cv::Mat DecodeImageBytes(const void* data, size_t size, int flags, std::string* error) {
  cv::Mat image;
  if (flags == cv::IMREAD_COLOR && DecodeJpegBgr(data, size, &image)) return image;
  const CodecsModule& module = Codecs();
  std::string why;
  if (module.decode && module.decode(data, size, flags, &image, &why)) return image;
  if (error) *error = module.decode ? why : ModuleMissing(module);
  image.release();
  return image;
}

}  // namespace fresco
