// Video sources: folders of images (sorted, filtered by extension, streamed lazily), video
// files through OpenCV's FFmpeg backend, and errors that name the frame.
#include "pipeline/core/video_source.h"

#include <filesystem>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "tests/test_support.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::StartsWith;

cv::Mat FrameImage(int i, cv::Size size = cv::Size(32, 24)) {
  cv::Mat image(size, CV_8UC3, cv::Scalar(10 * i, 255 - 10 * i, 7 * i));
  image.at<cv::Vec3b>(1, 2) = cv::Vec3b(1, 2, 3);
  return image;
}

std::unique_ptr<VideoSource> Open(const std::string& path) {
  std::unique_ptr<VideoSource> source;
  const Status status = OpenVideoSource(path, &source);
  EXPECT_TRUE(status.ok()) << status.message();
  return source;
}

TEST(VideoSourceTest, FolderFramesAreSortedByNameAndFiltered) {
  const std::string dir = testing::MakeTempDir("video");
  // Written out of order, with mixed-case extensions and files that are not frames.
  ASSERT_TRUE(cv::imwrite(dir + "/000002.PNG", FrameImage(2)));
  ASSERT_TRUE(cv::imwrite(dir + "/000000.png", FrameImage(0)));
  ASSERT_TRUE(cv::imwrite(dir + "/000001.Jpeg", FrameImage(1)));
  ASSERT_TRUE(cv::imwrite(dir + "/000003.bmp", FrameImage(3)));
  ASSERT_TRUE(cv::imwrite(dir + "/000004.tiff", FrameImage(4)));
  ASSERT_TRUE(cv::imwrite(dir + "/000005.ppm", FrameImage(5)));
  ASSERT_TRUE(cv::imwrite(dir + "/.hidden.png", FrameImage(9)));
  testing::WriteText(dir + "/notes.txt", "not a frame");
  fs::create_directories(dir + "/sub.png");  // a folder, not a frame

  auto source = Open(dir);
  ASSERT_TRUE(source);
  const std::vector<std::string> expected = {"000000.png", "000001.Jpeg", "000002.PNG",
                                             "000003.bmp", "000004.tiff", "000005.ppm"};
  EXPECT_EQ(source->FrameNames(), expected);
  EXPECT_EQ(source->FrameCount(), 6);
  EXPECT_EQ(source->Fps(), 30.0);
  Frame frame;
  Status status;
  for (int i = 0; i < 6; ++i) {
    ASSERT_TRUE(source->Next(&frame, &status)) << status.message();
    EXPECT_EQ(frame.index, i);
    EXPECT_EQ(frame.name, expected[i]);
    EXPECT_DOUBLE_EQ(frame.timestamp_s, i / 30.0);
    ASSERT_EQ(frame.bgr.type(), CV_8UC3);
    ASSERT_EQ(frame.bgr.size(), cv::Size(32, 24));
    if (i != 1) {  // lossless formats give the pixels back exactly
      EXPECT_EQ(cv::norm(frame.bgr, FrameImage(i), cv::NORM_INF), 0) << expected[i];
    }
  }
  EXPECT_FALSE(source->Next(&frame, &status));
  EXPECT_TRUE(status.ok());
}

TEST(VideoSourceTest, GreyAndAlphaImagesBecomeBgr) {
  const std::string dir = testing::MakeTempDir("video");
  ASSERT_TRUE(cv::imwrite(dir + "/a.png", cv::Mat(24, 32, CV_8UC1, cv::Scalar(77))));
  ASSERT_TRUE(cv::imwrite(dir + "/b.png", cv::Mat(24, 32, CV_8UC4, cv::Scalar(1, 2, 3, 0))));
  auto source = Open(dir);
  Frame frame;
  Status status;
  ASSERT_TRUE(source->Next(&frame, &status));
  EXPECT_EQ(frame.bgr.type(), CV_8UC3);
  EXPECT_EQ(frame.bgr.at<cv::Vec3b>(0, 0), cv::Vec3b(77, 77, 77));
  ASSERT_TRUE(source->Next(&frame, &status));
  EXPECT_EQ(frame.bgr.type(), CV_8UC3);
  EXPECT_EQ(frame.bgr.at<cv::Vec3b>(0, 0), cv::Vec3b(1, 2, 3));
}

TEST(VideoSourceTest, FramesAreReadLazily) {
  // Opening lists names only: a frame replaced after opening is read as it is then.
  const std::string dir = testing::MakeTempDir("video");
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(cv::imwrite(dir + "/" + std::to_string(i) + ".png", FrameImage(i)));
  }
  auto source = Open(dir);
  ASSERT_TRUE(cv::imwrite(dir + "/2.png", FrameImage(7)));
  Frame frame;
  Status status;
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(source->Next(&frame, &status));
  EXPECT_EQ(cv::norm(frame.bgr, FrameImage(7), cv::NORM_INF), 0);
}

TEST(VideoSourceTest, UndecodableFrameIsNamed) {
  const std::string dir = testing::MakeTempDir("video");
  ASSERT_TRUE(cv::imwrite(dir + "/000000.png", FrameImage(0)));
  testing::WriteText(dir + "/000001.png", "this is not a PNG");
  auto source = Open(dir);
  Frame frame;
  Status status;
  ASSERT_TRUE(source->Next(&frame, &status));
  EXPECT_FALSE(source->Next(&frame, &status));
  EXPECT_EQ(status.message(), dir + "/000001.png: cannot decode the image");
}

TEST(VideoSourceTest, FrameOfAnotherSizeIsNamed) {
  const std::string dir = testing::MakeTempDir("video");
  ASSERT_TRUE(cv::imwrite(dir + "/a.png", FrameImage(0)));
  ASSERT_TRUE(cv::imwrite(dir + "/b.png", FrameImage(1, cv::Size(16, 24))));
  auto source = Open(dir);
  Frame frame;
  Status status;
  ASSERT_TRUE(source->Next(&frame, &status));
  EXPECT_FALSE(source->Next(&frame, &status));
  EXPECT_EQ(status.message(), dir +
                                  "/b.png: frame size 16x24 differs from the first frame's "
                                  "32x24 (" +
                                  dir + "/a.png)");
}

TEST(VideoSourceTest, OpenErrorsNameThePath) {
  const std::string dir = testing::MakeTempDir("video");
  std::unique_ptr<VideoSource> source;
  Status status = OpenVideoSource(dir, &source);
  EXPECT_THAT(status.message(), StartsWith(dir + ": no image frames in the folder"));
  status = OpenVideoSource(dir + "/none.mp4", &source);
  EXPECT_EQ(status.message(), dir + "/none.mp4: no such file or folder");
  testing::WriteText(dir + "/junk.mp4", "not a video");
  status = OpenVideoSource(dir + "/junk.mp4", &source);
  EXPECT_THAT(status.message(), StartsWith(dir + "/junk.mp4: cannot open as a video"));
  status = OpenVideoSource("device:x", &source);
  EXPECT_THAT(status.message(), StartsWith("device:x: expected device:N"));
}

TEST(VideoSourceTest, VideoFileFramesAreNamedByIndex) {
  const std::string dir = testing::MakeTempDir("video");
  const std::string path = dir + "/clip.avi";
  {
    cv::VideoWriter writer(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0,
                           cv::Size(64, 48));
    ASSERT_TRUE(writer.isOpened());
    for (int i = 0; i < 8; ++i) writer.write(FrameImage(i, cv::Size(64, 48)));
  }
  auto source = Open(path);
  ASSERT_TRUE(source);
  EXPECT_DOUBLE_EQ(source->Fps(), 10.0);
  EXPECT_EQ(source->FrameCount(), 8);
  EXPECT_TRUE(source->FrameNames().empty());
  Frame frame;
  Status status;
  int n = 0;
  while (source->Next(&frame, &status)) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", n);
    EXPECT_EQ(frame.index, n);
    EXPECT_EQ(frame.name, name);
    EXPECT_DOUBLE_EQ(frame.timestamp_s, n / 10.0);
    EXPECT_EQ(frame.bgr.type(), CV_8UC3);
    EXPECT_EQ(frame.bgr.size(), cv::Size(64, 48));
    // MJPEG is lossy: colours come back close.
    EXPECT_LT(cv::norm(frame.bgr, FrameImage(n, cv::Size(64, 48)), cv::NORM_L1) / (64 * 48 * 3),
              4.0);
    ++n;
  }
  EXPECT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(n, 8);
}

// A video file's frames are passed over without converting them (PeekNext grabs, SkipNext
// drops): the frames read after them are the right ones, named by their index.
TEST(VideoSourceTest, VideoFileFramesAreSkippedByIndex) {
  const std::string path = testing::MakeTempDir("video-skip") + "/clip.avi";
  {
    cv::VideoWriter writer(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0,
                           cv::Size(64, 48));
    ASSERT_TRUE(writer.isOpened());
    for (int i = 0; i < 8; ++i) writer.write(FrameImage(3 * i, cv::Size(64, 48)));
  }
  auto source = Open(path);
  ASSERT_TRUE(source);
  Frame frame;
  Status status;
  std::vector<int> read;
  for (int i = 0; i < 8; ++i) {
    ASSERT_TRUE(source->PeekNext(&frame)) << i;
    EXPECT_EQ(frame.index, i);
    EXPECT_TRUE(frame.bgr.empty());
    if (i % 3 != 1) {  // frames 1, 4 and 7 read, the others skipped
      source->SkipNext();
      continue;
    }
    ASSERT_TRUE(source->Next(&frame, &status)) << status.message();
    EXPECT_EQ(frame.index, i);
    EXPECT_LT(cv::norm(frame.bgr, FrameImage(3 * i, cv::Size(64, 48)), cv::NORM_L1) / (64 * 48 * 3),
              4.0)
        << "frame " << i << " is another frame's";
    read.push_back(i);
  }
  EXPECT_EQ(read, std::vector<int>({1, 4, 7}));
  EXPECT_FALSE(source->PeekNext(&frame));
  EXPECT_FALSE(source->Next(&frame, &status));
  EXPECT_TRUE(status.ok()) << status.message();
}

TEST(VideoSourceTest, ReadsARealVideo) {
  FRESCO_REQUIRE_SHARED_DATA();
  auto source = Open(testing::SharedDataDir() + "/video-intel-static-cam/car-detection.mp4");
  ASSERT_TRUE(source);
  EXPECT_GT(source->Fps(), 0);
  Frame frame;
  Status status;
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(source->Next(&frame, &status)) << status.message();
    EXPECT_EQ(frame.bgr.size(), cv::Size(768, 432));
  }
  EXPECT_EQ(frame.name, "000004.png");
  // To the end: every frame its header declares, and no "truncated" error (the check for
  // cut-off videos must not fire on a whole one).
  int frames = 5;
  while (source->Next(&frame, &status)) ++frames;
  EXPECT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(frames, source->FrameCount());
  EXPECT_EQ(frames, 377);  // ffprobe -count_frames
}

// Seek (stepping back in the app): a video file goes back to the very frame asked for (read
// again from the start: the same bytes, whatever the codec's key frames), then on; a folder too.
TEST(VideoSourceTest, SeekBackGivesTheSameFramesAgain) {
  FRESCO_REQUIRE_SHARED_DATA();
  for (const std::string& path :
       {testing::SharedDataDir() + "/video-intel-static-cam/car-detection.mp4", std::string()}) {
    std::string where = path;
    if (where.empty()) {  // a folder
      where = testing::MakeTempDir("seek-folder");
      for (int i = 0; i < 12; ++i)
        cv::imwrite(where + "/" + std::to_string(100 + i) + ".png", FrameImage(i));
    }
    auto source = Open(where);
    ASSERT_TRUE(source);
    std::vector<cv::Mat> first;
    Frame frame;
    Status status;
    for (int i = 0; i < 12; ++i) {
      ASSERT_TRUE(source->Next(&frame, &status)) << status.message();
      first.push_back(frame.bgr.clone());
    }
    for (const int back : {7, 2, 9}) {
      ASSERT_TRUE(source->Seek(back)) << where;
      for (int i = back; i < 12; ++i) {
        ASSERT_TRUE(source->Next(&frame, &status)) << status.message();
        EXPECT_EQ(frame.index, i) << where;
        EXPECT_EQ(cv::norm(frame.bgr, first[i], cv::NORM_INF), 0) << where << " frame " << i;
      }
    }
  }
}

}  // namespace
}  // namespace fresco
