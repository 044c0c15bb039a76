// Images as saved painting states keep them (PackedImage): byte for byte back, the blocks all
// zero not stored, the blocks equal to an earlier packing of the image shared with it, and an
// image packed against one mostly equal to it storing only the blocks where they differ.
#include "pipeline/paint/packed_image.h"

#include <cstring>
#include <set>

#include <gtest/gtest.h>

namespace fresco {
namespace {

constexpr size_t kBlock = PackedImage::kBlockBytes;

size_t HeldBytes(const PackedImage& image, std::set<const void*>* blocks) {
  size_t bytes = 0;
  image.ForEachBlock([&](const void* block, size_t n) {
    if (blocks->insert(block).second) bytes += n;
  });
  return bytes;
}

bool SameBytes(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() &&
         std::memcmp(a.data, b.data, a.total() * a.elemSize()) == 0;
}

// Five whole blocks and 100 bytes (as 4 rows of bytes), set in block 0 and in the short last
// one (to 0x80: the sign of a float -0, not zero).
cv::Mat PaintedInPlaces() {
  const int row = static_cast<int>((5 * kBlock + 100) / 4);
  cv::Mat image = cv::Mat::zeros(4, row, CV_8U);
  image.data[7] = 12;
  image.data[5 * kBlock + 99] = 0x80;
  return image;
}

TEST(PackedImage, UnpacksByteForByteAndStoresOnlyTheBlocksNotZero) {
  const cv::Mat image = PaintedInPlaces();
  const PackedImage packed(image, nullptr);
  EXPECT_EQ(packed.raw_bytes(), 5 * kBlock + 100);
  EXPECT_TRUE(SameBytes(packed.Unpacked(), image));
  std::set<const void*> blocks;
  EXPECT_EQ(HeldBytes(packed, &blocks), kBlock + 100);
  EXPECT_TRUE(PackedImage(cv::Mat(), nullptr).Unpacked().empty());
  // A view into a larger image (rows not contiguous) packs as its own pixels.
  const cv::Mat view = image(cv::Rect(5, 1, 60, 3));
  EXPECT_TRUE(SameBytes(PackedImage(view, nullptr).Unpacked(), view.clone()));
}

TEST(PackedImage, BlocksEqualToTheEarlierPackingAreSharedTheOthersNot) {
  cv::Mat image = PaintedInPlaces();
  const PackedImage first(image, nullptr);
  image.data[3 * kBlock + 5] = 1;  // block 3, zero before
  image.data[8] = 3;               // block 0, changed
  const PackedImage second(image, &first);
  std::set<const void*> blocks;
  HeldBytes(first, &blocks);
  EXPECT_EQ(HeldBytes(second, &blocks), 2 * kBlock);  // blocks 0 and 3 new, the last shared
  EXPECT_TRUE(SameBytes(second.Unpacked(), image));
  EXPECT_FALSE(SameBytes(first.Unpacked(), image));  // the first as it was packed
  // Another size: nothing shared.
  const PackedImage other(image.reshape(1, 2), &first);
  std::set<const void*> none;
  HeldBytes(first, &none);
  EXPECT_EQ(HeldBytes(other, &none), 2 * kBlock + 100);
}

TEST(PackedImage, AgainstAReferenceOnlyTheBlocksThatDifferAreStored) {
  cv::Mat store(64, 256, CV_32FC4);  // 256 KB of noise: every block stored on its own
  cv::randu(store, -1000.0f, 1000.0f);
  cv::Mat shadow = store.clone();
  shadow.at<cv::Vec4f>(40, 3)[2] = 7.0f;
  const PackedImage packed(shadow, nullptr, &store);
  std::set<const void*> blocks;
  EXPECT_EQ(HeldBytes(packed, &blocks), kBlock);
  EXPECT_TRUE(SameBytes(packed.Unpacked(&store), shadow));
  std::set<const void*> alone;
  EXPECT_EQ(HeldBytes(PackedImage(shadow, nullptr), &alone), shadow.total() * shadow.elemSize());
}

TEST(PackedImage, ALargeImageUnpacksByteForByteInStripes) {
  // 3 MB and a short last block: unpacked in stripes on the threads, alone and against a
  // reference, blocks all zero (or equal to the reference's) between blocks stored.
  cv::Mat store(513, 383, CV_32FC4);
  cv::randu(store, -1000.0f, 1000.0f);
  cv::Mat image = store.clone();
  image.rowRange(100, 300).setTo(cv::Scalar::all(0));
  image.at<cv::Vec4f>(512, 382)[3] = -0.0f;  // the last byte's sign bit
  const PackedImage alone(image, nullptr);
  EXPECT_TRUE(SameBytes(alone.Unpacked(), image));
  cv::Mat shadow = store.clone();
  shadow.at<cv::Vec4f>(7, 5)[1] = 3.0f;
  shadow.at<cv::Vec4f>(400, 200)[0] = -2.0f;
  shadow.at<cv::Vec4f>(512, 382)[3] = 9.0f;
  const PackedImage against(shadow, nullptr, &store);
  std::set<const void*> blocks;
  EXPECT_EQ(HeldBytes(against, &blocks), 2 * kBlock + (shadow.total() * 16) % kBlock);
  EXPECT_TRUE(SameBytes(against.Unpacked(&store), shadow));
}

}  // namespace
}  // namespace fresco
