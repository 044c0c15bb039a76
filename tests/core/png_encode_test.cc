#include "pipeline/core/png_encode.h"

#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

namespace fresco {
namespace {

// Noise plus smooth gradients: both the filter and zlib see data they can and cannot
// predict, and every byte value occurs.
cv::Mat TestImage(int type, int width, int height) {
  cv::Mat image(height, width, type);
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> noise(0, 255);
  for (int r = 0; r < height; ++r) {
    uint8_t* row = image.ptr<uint8_t>(r);
    for (int i = 0; i < width * image.channels(); ++i)
      row[i] = static_cast<uint8_t>(i % 3 == 0 ? noise(rng) : (r + i) & 255);
  }
  return image;
}

TEST(PngEncodeTest, DecodesToExactlyTheSamePixels) {
  for (const int type : {CV_8UC3, CV_8UC1}) {
    // A view into a larger image (rows not contiguous) must be read row by row.
    const cv::Mat big = TestImage(type, 333, 201);
    const cv::Mat image = big(cv::Rect(3, 1, 320, 200));
    std::vector<uint8_t> png;
    ASSERT_TRUE(EncodeFastDecodingPng(image, &png).ok());
    const cv::Mat decoded = cv::imdecode(png, cv::IMREAD_UNCHANGED);
    ASSERT_EQ(decoded.type(), type);
    ASSERT_EQ(decoded.size(), image.size());
    EXPECT_EQ(cv::norm(decoded, image, cv::NORM_INF), 0.0) << "type " << type;
    // Colour stays BGR: the first channel is the noisy one.
    if (type == CV_8UC3) EXPECT_EQ(decoded.at<cv::Vec3b>(5, 7), image.at<cv::Vec3b>(5, 7));
  }
}

TEST(PngEncodeTest, RefusesWhatPngCannotHoldLikeThis) {
  std::vector<uint8_t> png = {1, 2, 3};
  const Status s = EncodeFastDecodingPng(cv::Mat(10, 10, CV_32F, cv::Scalar(1)), &png);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("8-bit grey or BGR"), std::string::npos) << s.message();
  EXPECT_FALSE(EncodeFastDecodingPng(cv::Mat(), &png).ok());
  EXPECT_FALSE(EncodeFastDecodingPng(cv::Mat(4, 4, CV_8UC4), &png).ok());
}

}  // namespace
}  // namespace fresco
