#include "pipeline/core/jpeg_decode.h"

#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "pipeline/core/image_io.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

cv::Mat TestImage(int type, int width, int height) {
  cv::Mat image(height, width, type);
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> noise(0, 255);
  for (int r = 0; r < height; ++r) {
    uint8_t* row = image.ptr<uint8_t>(r);
    for (int i = 0; i < width * image.channels(); ++i)
      row[i] = static_cast<uint8_t>(i % 5 == 0 ? noise(rng) : (3 * r + i) & 255);
  }
  return image;
}

std::string Encode(const cv::Mat& image, const std::vector<int>& params) {
  std::vector<uint8_t> buffer;
  EXPECT_TRUE(cv::imencode(".jpg", image, buffer, params));
  return std::string(buffer.begin(), buffer.end());
}

cv::Mat OpenCvDecode(const std::string& bytes) {
  return cv::imdecode(
      cv::Mat(1, static_cast<int>(bytes.size()), CV_8U, const_cast<char*>(bytes.data())),
      cv::IMREAD_COLOR);
}

// An APP1 segment with an EXIF orientation tag, inserted after the SOI marker.
std::string WithOrientation(const std::string& jpeg, int orientation) {
  std::string tiff = std::string("II*\0", 4) + std::string("\x08\0\0\0", 4) +  // IFD0 at 8
                     std::string("\x01\0", 2) +                                // one entry
                     std::string("\x12\x01\x03\0\x01\0\0\0", 8) +              // 0x0112 SHORT x1
                     std::string(1, static_cast<char>(orientation)) + std::string(3, '\0') +
                     std::string(4, '\0');  // no next IFD
  const std::string payload = std::string("Exif\0\0", 6) + tiff;
  const size_t length = payload.size() + 2;
  std::string segment = "\xff\xe1";
  segment += static_cast<char>(length >> 8);
  segment += static_cast<char>(length & 255);
  return jpeg.substr(0, 2) + segment + payload + jpeg.substr(2);
}

TEST(JpegDecodeTest, SamePixelsAsOpenCv) {
  struct Case {
    int type, width, height;
    std::vector<int> params;
  };
  const std::vector<Case> cases = {
      {CV_8UC3, 333, 201, {cv::IMWRITE_JPEG_QUALITY, 90}},  // 4:2:0, odd size
      {CV_8UC3, 64, 48, {cv::IMWRITE_JPEG_QUALITY, 75, cv::IMWRITE_JPEG_RST_INTERVAL, 2}},
      {CV_8UC3, 97, 130, {cv::IMWRITE_JPEG_PROGRESSIVE, 1, cv::IMWRITE_JPEG_OPTIMIZE, 1}},
      {CV_8UC1, 121, 77, {cv::IMWRITE_JPEG_QUALITY, 95}},  // grey: decoded to BGR
  };
  for (const Case& c : cases) {
    const std::string bytes = Encode(TestImage(c.type, c.width, c.height), c.params);
    cv::Mat ours;
    ASSERT_TRUE(DecodeJpegBgr(bytes, &ours)) << c.width << "x" << c.height;
    const cv::Mat theirs = OpenCvDecode(bytes);
    ASSERT_EQ(ours.type(), CV_8UC3);
    ASSERT_EQ(ours.size(), theirs.size());
    EXPECT_EQ(cv::norm(ours, theirs, cv::NORM_INF), 0.0) << c.width << "x" << c.height;
  }
}

TEST(JpegDecodeTest, UprightExifDecodedHereRotatedLeftToOpenCv) {
  const cv::Mat image = TestImage(CV_8UC3, 40, 24);
  const std::string plain = Encode(image, {cv::IMWRITE_JPEG_QUALITY, 90});
  cv::Mat ours;
  ASSERT_TRUE(DecodeJpegBgr(WithOrientation(plain, 1), &ours));
  EXPECT_EQ(cv::norm(ours, OpenCvDecode(plain), cv::NORM_INF), 0.0);
  // Rotated a quarter turn: this path declines, and ReadImage gives what OpenCV gives.
  const std::string rotated = WithOrientation(plain, 6);
  EXPECT_FALSE(DecodeJpegBgr(rotated, &ours));
  EXPECT_TRUE(ours.empty());
  const cv::Mat opencv = OpenCvDecode(rotated);
  ASSERT_EQ(opencv.size(), cv::Size(24, 40));  // OpenCV applies the orientation
  const std::string path = ::testing::TempDir() + "/rotated.jpg";
  {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    std::fwrite(rotated.data(), 1, rotated.size(), f);
    std::fclose(f);
  }
  cv::Mat read;
  ASSERT_TRUE(ReadImage(path, &read, cv::IMREAD_COLOR).ok());
  EXPECT_EQ(cv::norm(read, opencv, cv::NORM_INF), 0.0);
}

TEST(JpegDecodeTest, DeclinesWhatIsNotAJpegAndCorruptData) {
  cv::Mat out;
  EXPECT_FALSE(DecodeJpegBgr("", &out));
  EXPECT_FALSE(DecodeJpegBgr(std::string("\x89PNG\r\n\x1a\n", 8), &out));
  std::string bytes = Encode(TestImage(CV_8UC3, 50, 40), {cv::IMWRITE_JPEG_QUALITY, 90});
  // A broken frame header (precision 0): libjpeg's error, reported as a decline, no crash.
  const size_t sof = bytes.find("\xff\xc0", 2);
  ASSERT_NE(sof, std::string::npos);
  bytes[sof + 4] = 0;
  EXPECT_FALSE(DecodeJpegBgr(bytes, &out));
  EXPECT_TRUE(out.empty());
}

TEST(JpegDecodeTest, RealPhotosSameAsOpenCv) {
  FRESCO_REQUIRE_SHARED_DATA();
  const std::filesystem::path dir =
      std::filesystem::path(testing::SharedDataDir()) / "sceaux-castle-openmvs" / "images";
  if (!std::filesystem::exists(dir)) GTEST_SKIP() << dir << " is absent";
  int compared = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".jpg" || compared >= 3) continue;
    cv::Mat ours;
    ASSERT_TRUE(ReadImage(entry.path().string(), &ours, cv::IMREAD_COLOR).ok());
    const cv::Mat theirs = cv::imread(entry.path().string(), cv::IMREAD_COLOR);
    ASSERT_EQ(ours.size(), theirs.size());
    EXPECT_EQ(cv::norm(ours, theirs, cv::NORM_INF), 0.0) << entry.path();
    ++compared;
  }
  EXPECT_EQ(compared, 3);
}

}  // namespace
}  // namespace fresco
