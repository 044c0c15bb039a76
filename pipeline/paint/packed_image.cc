#include "pipeline/paint/packed_image.h"

#include <algorithm>
#include <cstring>

#include <opencv2/core/utility.hpp>

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

// `n` bytes of a block XOR the reference's into `out`, a word at a time (a call of
// cv::bitwise_xor per 4 KB block costs more than the XOR itself).
void XorInto(const uint8_t* bytes, const uint8_t* reference, size_t n, uint8_t* out) {
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    uint64_t a, b;
    std::memcpy(&a, bytes + i, 8);
    std::memcpy(&b, reference + i, 8);
    a ^= b;
    std::memcpy(out + i, &a, 8);
  }
  for (; i < n; ++i) out[i] = bytes[i] ^ reference[i];
}

// `n` bytes XOR the reference's into `out` (no reference: the bytes).
const uint8_t* Xored(const uint8_t* bytes, const uint8_t* reference, size_t n, uint8_t* out) {
  if (!reference) return bytes;
  XorInto(bytes, reference, n, out);
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
  cv::Mat against;
  if (against_reference_) {
    CV_Assert(reference && reference->size() == image.size() && reference->type() == type_);
    against = reference->isContinuous() ? *reference : reference->clone();
  }
  // One pass: a block stored is copied (XOR the reference's, bit for bit whatever the type),
  // a block all zero is zeros (the reference's bytes where packed against one). A large image
  // in stripes of 1 MB on the threads (a restore is bound by writing its bytes).
  const auto unpack = [&](const cv::Range& range) {
    for (size_t b = range.start; b < static_cast<size_t>(range.end); ++b) {
      const size_t offset = b * kBlockBytes, n = std::min(kBlockBytes, raw_bytes_ - offset);
      uint8_t* to = image.data + offset;
      const uint8_t* from = blocks_[b] ? blocks_[b]->data() : nullptr;
      if (against.empty()) {
        if (from)
          std::memcpy(to, from, n);
        else
          std::memset(to, 0, n);
      } else if (from) {
        XorInto(from, against.data + offset, n, to);
      } else {
        std::memcpy(to, against.data + offset, n);
      }
    }
  };
  constexpr size_t kStripeBlocks = (size_t{1} << 20) / kBlockBytes;
  const cv::Range all(0, static_cast<int>(blocks_.size()));
  if (blocks_.size() >= 2 * kStripeBlocks)
    cv::parallel_for_(all, unpack, static_cast<double>(blocks_.size() / kStripeBlocks));
  else
    unpack(all);
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
