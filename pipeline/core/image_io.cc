#include "pipeline/core/image_io.h"

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/image_codecs.h"

namespace fresco {

namespace {

std::string InParentheses(const std::string& why) { return why.empty() ? "" : " (" + why + ")"; }

// The image encoded in the format `path`'s extension names (PNG without one).
Status EncodeImage(const std::string& path, const cv::Mat& image, std::string* encoded) {
  if (image.empty()) return Status::Internal(path + ": empty image");
  const std::string ext = std::filesystem::path(path).extension().string();
  std::vector<uchar> bytes;
  std::string why;
  if (!EncodeImageBytes(ext.empty() ? ".png" : ext, image, &bytes, &why))
    return Status::OutputError(path + ": could not encode image" + InParentheses(why));
  encoded->assign(bytes.begin(), bytes.end());
  return Status::Ok();
}

}  // namespace

Status WriteImageAtomic(const std::string& path, const cv::Mat& image) {
  std::string encoded;
  FRESCO_RETURN_IF_ERROR(EncodeImage(path, image, &encoded));
  return WriteFileAtomic(path, encoded);
}

Status WriteImage(const std::string& path, const cv::Mat& image) {
  std::string encoded;
  FRESCO_RETURN_IF_ERROR(EncodeImage(path, image, &encoded));
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return Status::OutputError(path + ": cannot open for writing: " + std::strerror(errno));
  out.write(encoded.data(), static_cast<std::streamsize>(encoded.size()));
  out.close();
  if (!out) return Status::OutputError(path + ": write failed: " + std::strerror(errno));
  return Status::Ok();
}

namespace {

uint32_t BigEndian32(const unsigned char* p) {
  return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | uint32_t(p[3]);
}

// Truncated or mangled PNG and JPEG files are caught here, before the decoder sees them:
// libpng and libjpeg print their own complaints on stderr (the CLI promises one line), and
// libjpeg decodes a truncated file without failing (grey where the data stopped).
Status CheckImageBytes(const std::string& path, const std::string& bytes) {
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  const size_t size = bytes.size();
  static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (size >= 8 && std::memcmp(data, kPng, 8) == 0) {
    // Chunks: length (4), type (4), data (length), CRC (4), up to IEND.
    for (size_t at = 8;;) {
      if (at + 12 > size || at + 12 + BigEndian32(data + at) > size) {
        return Status::Error(path + ": truncated PNG (" + std::to_string(size) +
                             " bytes; its chunks run past the end of the file)");
      }
      if (std::memcmp(data + at + 4, "IEND", 4) == 0) return Status::Ok();
      at += 12 + BigEndian32(data + at);
    }
  }
  if (size >= 3 && data[0] == 0xff && data[1] == 0xd8 && data[2] == 0xff) {
    // The end-of-image marker, allowing for padding after it.
    const size_t from = size > 4096 ? size - 4096 : 2;
    for (size_t i = size - 1; i > from; --i)
      if (data[i - 1] == 0xff && data[i] == 0xd9) return Status::Ok();
    return Status::Error(path + ": truncated JPEG (no end-of-image marker)");
  }
  return Status::Ok();
}

}  // namespace

Status ReadImage(const std::string& path, cv::Mat* image, int flags) {
  std::string bytes;
  FRESCO_RETURN_IF_ERROR(ReadFileToString(path, &bytes));
  FRESCO_RETURN_IF_ERROR(CheckImageBytes(path, bytes));
  std::string why;
  *image = DecodeImageBytes(bytes.data(), bytes.size(), flags, &why);
  if (image->empty()) return Status::Error(path + ": cannot decode the image" + InParentheses(why));
  return Status::Ok();
}

}  // namespace fresco
