#include "pipeline/core/image_codecs.h"

#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

namespace fresco {
namespace {

// Noise in one channel, gradients in the others: zlib and the filter see data they can and
// cannot predict.
cv::Mat TestImage(int type, int width, int height) {
  cv::Mat image(height, width, type);
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> noise(0, 65535);
  const int values = width * image.channels();
  for (int r = 0; r < height; ++r) {
    for (int i = 0; i < values; ++i) {
      const int v = i % 4 == 0 ? noise(rng) : 97 * r + 13 * i;
      if (image.depth() == CV_8U)
        image.ptr<uint8_t>(r)[i] = static_cast<uint8_t>(v);
      else
        image.ptr<uint16_t>(r)[i] = static_cast<uint16_t>(v);
    }
  }
  return image;
}

std::vector<uchar> OpenCvEncode(const std::string& ext, const cv::Mat& image) {
  std::vector<uchar> bytes;
  EXPECT_TRUE(cv::imencode(ext, image, bytes));
  return bytes;
}

TEST(ImageCodecs, PngIsEncodedToTheBytesOpenCVWrites) {
  for (const int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4}) {
    // A view into a larger image (rows not contiguous), large enough for several IDAT chunks.
    const cv::Mat big = TestImage(type, 517, 300);
    const cv::Mat image = big(cv::Rect(5, 2, 509, 297));
    std::vector<uchar> ours;
    ASSERT_TRUE(EncodeImageBytes(".png", image, &ours)) << "type " << type;
    EXPECT_EQ(ours, OpenCvEncode(".png", image)) << "type " << type;
    EXPECT_TRUE(EncodeImageBytes(".PNG", image, &ours));
    EXPECT_EQ(ours, OpenCvEncode(".png", image)) << "type " << type;
  }
}

TEST(ImageCodecs, OtherFormatsAndTypesGoThroughOpenCVsCodecs) {
  const cv::Mat image = TestImage(CV_8UC3, 64, 48);
  std::vector<uchar> ours;
  ASSERT_TRUE(EncodeImageBytes(".jpg", image, &ours));
  EXPECT_EQ(ours, OpenCvEncode(".jpg", image));
  ASSERT_TRUE(EncodeImageBytes(".bmp", image, &ours));
  EXPECT_EQ(ours, OpenCvEncode(".bmp", image));
  const cv::Mat floats(8, 8, CV_32FC1, cv::Scalar(0.5));  // PNG of floats: OpenCV converts
  ASSERT_TRUE(EncodeImageBytes(".png", floats, &ours));
  EXPECT_EQ(ours, OpenCvEncode(".png", floats));
  std::string why;
  EXPECT_FALSE(EncodeImageBytes(".png", cv::Mat(), &ours, &why));  // OpenCV throws
  EXPECT_FALSE(why.empty());
  EXPECT_FALSE(EncodeImageBytes(".nosuchformat", image, &ours, &why));
}

TEST(ImageCodecs, DecodesToThePixelsOpenCVReads) {
  const cv::Mat bgra = TestImage(CV_8UC4, 90, 70), bgr = TestImage(CV_8UC3, 90, 70);
  for (const std::string ext : {".png", ".jpg", ".bmp"}) {
    // A colour JPEG decoded in colour is decoded here, the rest by the module.
    const std::vector<uchar> bytes = OpenCvEncode(ext, ext == ".jpg" ? bgr : bgra);
    for (const int flags : {cv::IMREAD_UNCHANGED, cv::IMREAD_COLOR, cv::IMREAD_GRAYSCALE}) {
      const cv::Mat ours = DecodeImageBytes(bytes.data(), bytes.size(), flags);
      const cv::Mat theirs = cv::imdecode(bytes, flags);
      ASSERT_FALSE(theirs.empty());
      ASSERT_EQ(ours.type(), theirs.type()) << ext << " flags " << flags;
      ASSERT_EQ(ours.size(), theirs.size());
      EXPECT_EQ(cv::norm(ours, theirs, cv::NORM_INF), 0.0) << ext << " flags " << flags;
    }
  }
  const std::string junk = "not an image at all";
  std::string why = "x";
  EXPECT_TRUE(DecodeImageBytes(junk.data(), junk.size(), cv::IMREAD_COLOR, &why).empty());
  EXPECT_TRUE(why.empty());
}

// The `fresco` program reads folders of JPEG photos and writes PNG pages without loading
// OpenCV's image codecs or its video reader (and the libraries they bring), only when a run
// needs them.
TEST(ImageCodecs, TheFrescoProgramDoesNotLinkOpenCVsCodecsOrVideoReader) {
  const char* binary = std::getenv("FRESCO_BINARY");
  if (!binary) GTEST_SKIP() << "FRESCO_BINARY is not set (CTest sets it)";
  FILE* pipe = popen(("ldd '" + std::string(binary) + "'").c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string libraries;
  char buffer[4096];
  for (size_t n; (n = fread(buffer, 1, sizeof buffer, pipe)) > 0;) libraries.append(buffer, n);
  ASSERT_EQ(pclose(pipe), 0) << libraries;
  ASSERT_NE(libraries.find("libopencv_core"), std::string::npos) << libraries;
  EXPECT_EQ(libraries.find("libopencv_imgcodecs"), std::string::npos) << libraries;
  EXPECT_EQ(libraries.find("libopencv_videoio"), std::string::npos) << libraries;
  EXPECT_EQ(libraries.find("libgdal"), std::string::npos) << libraries;
}

}  // namespace
}  // namespace fresco
