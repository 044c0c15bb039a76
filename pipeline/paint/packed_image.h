// An image as a saved painting state keeps it (PaintSession::SaveState): its bytes in blocks,
// a block all zero not stored (the texels never painted, the gutters, the sums not yet made),
// the others shared with the same image of an earlier state where their bytes are equal (what
// painting did not change between two states is stored once). Blocks are never written after
// packing, so sharing them is safe; unpacking gives the image byte for byte.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <opencv2/core.hpp>

namespace fresco {

class PackedImage {
 public:
  static constexpr size_t kBlockBytes = 4096;

  PackedImage() = default;
  // `earlier`: the same image packed before (null, or of another size or type: nothing shared).
  // `reference` (optional): an image mostly equal to this one (a texel store's shadow and the
  // store): the blocks kept are the bytes XOR the reference's, all zero where equal; unpacking
  // then needs the same reference.
  PackedImage(const cv::Mat& image, const PackedImage* earlier, const cv::Mat* reference = nullptr);

  // A fresh image (an empty one: empty); `reference` the one it was packed against.
  cv::Mat Unpacked(const cv::Mat* reference = nullptr) const;
  void CopyTo(void* bytes) const;  // its raw_bytes() bytes (packed without a reference)
  size_t raw_bytes() const { return raw_bytes_; }
  // Each block stored (the block's identity, its bytes): blocks shared across states count once.
  template <typename F>
  void ForEachBlock(F f) const {
    for (const auto& block : blocks_)
      if (block) f(static_cast<const void*>(block.get()), block->size());
  }

 private:
  int rows_ = 0, cols_ = 0, type_ = 0;
  size_t raw_bytes_ = 0;
  bool against_reference_ = false;
  std::vector<std::shared_ptr<const std::vector<uint8_t>>> blocks_;  // null: all zero
};

}  // namespace fresco
