#include "pipeline/paint/packed_image.h"

#include <algorithm>
#include <cstring>

namespace fresco {
namespace {

bool AllZero(const uint8_t* bytes, size_t n) {
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    uint64_t word;
    std::memcpy(&word, bytes + i, 8);
    if (word != 0) return false;
  }
  for (; i < n; ++i)
    if (bytes[i] != 0) return false;
  return true;
}

// `n` bytes XOR the reference's into `out` (no reference: the bytes).
const uint8_t* Xored(const uint8_t* bytes, const uint8_t* reference, size_t n, uint8_t* out) {
  if (!reference) return bytes;
  cv::Mat into(1, static_cast<int>(n), CV_8U, out);
  cv::bitwise_xor(cv::Mat(1, static_cast<int>(n), CV_8U, const_cast<uint8_t*>(bytes)),
                  cv::Mat(1, static_cast<int>(n), CV_8U, const_cast<uint8_t*>(reference)), into);
  return out;
}

}  // namespace

PackedImage::PackedImage(const cv::Mat& image, const PackedImage* earlier,
                         const cv::Mat* reference) {
  if (image.empty()) return;
  const cv::Mat whole = image.isContinuous() ? image : image.clone();
  rows_ = whole.rows, cols_ = whole.cols, type_ = whole.type();
  raw_bytes_ = whole.total() * whole.elemSize();
  cv::Mat against;
  if (reference && reference->size() == whole.size() && reference->type() == type_)
    against = reference->isContinuous() ? *reference : reference->clone();
  against_reference_ = !against.empty();
  const bool shares = earlier && earlier->rows_ == rows_ && earlier->cols_ == cols_ &&
                      earlier->type_ == type_ && earlier->against_reference_ == against_reference_;
  const size_t count = (raw_bytes_ + kBlockBytes - 1) / kBlockBytes;
  blocks_.resize(count);
  uint8_t xored[kBlockBytes];
  for (size_t b = 0; b < count; ++b) {
    const size_t n = std::min(kBlockBytes, raw_bytes_ - b * kBlockBytes);
    const uint8_t* bytes =
        Xored(whole.data + b * kBlockBytes,
              against_reference_ ? against.data + b * kBlockBytes : nullptr, n, xored);
    if (AllZero(bytes, n)) continue;
    const auto& before = shares ? earlier->blocks_[b] : nullptr;
    if (before && std::memcmp(before->data(), bytes, n) == 0) {
      blocks_[b] = before;
      continue;
    }
    blocks_[b] = std::make_shared<const std::vector<uint8_t>>(bytes, bytes + n);
  }
}

cv::Mat PackedImage::Unpacked(const cv::Mat* reference) const {
  if (raw_bytes_ == 0) return cv::Mat();
  cv::Mat image(rows_, cols_, type_);
  CopyTo(image.data);
  if (against_reference_) {
    CV_Assert(reference && reference->size() == image.size() && reference->type() == type_);
    cv::bitwise_xor(image, *reference, image);  // bit for bit, whatever the type
  }
  return image;
}

void PackedImage::CopyTo(void* to) const {
  uint8_t* bytes = static_cast<uint8_t*>(to);
  for (size_t b = 0; b < blocks_.size(); ++b, bytes += kBlockBytes) {
    const size_t n = std::min(kBlockBytes, raw_bytes_ - b * kBlockBytes);
    if (blocks_[b])
      std::memcpy(bytes, blocks_[b]->data(), n);
    else
      std::memset(bytes, 0, n);
  }
}

}  // namespace fresco
