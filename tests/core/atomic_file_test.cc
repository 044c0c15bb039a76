// Atomic writes: the target is either the old or the new file, never half-written; failures
// leave the previous file intact and no temp file behind; messages name the path.
#include "pipeline/core/atomic_file.h"

#include <sys/stat.h>

#include <filesystem>
#include <stdexcept>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "tests/test_support.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::StartsWith;

int CountEntries(const std::string& dir) {
  int n = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++n;
  return n;
}

TEST(AtomicFileTest, WritesAndReadsBack) {
  const std::string dir = testing::MakeTempDir("atomic");
  const std::string path = dir + "/a.txt";
  std::string binary("line\n\0with nul\r\n", 16);
  ASSERT_TRUE(WriteFileAtomic(path, binary).ok());
  std::string read;
  ASSERT_TRUE(ReadFileToString(path, &read).ok());
  EXPECT_EQ(read, binary);
  ASSERT_TRUE(WriteFileAtomic(path, "").ok());
  ASSERT_TRUE(ReadFileToString(path, &read).ok());
  EXPECT_EQ(read, "");
  EXPECT_EQ(CountEntries(dir), 1);  // no temp file left behind
}

TEST(AtomicFileTest, ReplacesAndKeepsTheFileMode) {
  const std::string dir = testing::MakeTempDir("atomic");
  const std::string path = dir + "/a.txt";
  ASSERT_TRUE(WriteFileAtomic(path, "old").ok());
  struct stat st;
  ASSERT_EQ(stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0644u);  // not mkstemp's 0600
  chmod(path.c_str(), 0640);
  ASSERT_TRUE(WriteFileAtomic(path, "new").ok());
  EXPECT_EQ(testing::ReadText(path), "new");
  ASSERT_EQ(stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0640u);
}

TEST(AtomicFileTest, FailedWriteKeepsThePreviousFile) {
  const std::string dir = testing::MakeTempDir("atomic");
  const std::string path = dir + "/a.txt";
  ASSERT_TRUE(WriteFileAtomic(path, "previous").ok());
  std::string temp_seen;
  Status status = WriteFileAtomicWith(path, [&](const std::string& temp) {
    temp_seen = temp;
    testing::WriteText(temp, "half-writ");
    return Status::Error(path + ": disk full (simulated)");
  });
  EXPECT_EQ(status.message(), path + ": disk full (simulated)");
  EXPECT_EQ(testing::ReadText(path), "previous");
  EXPECT_FALSE(fs::exists(temp_seen));
  EXPECT_EQ(CountEntries(dir), 1);

  // A writer that throws is a failure too.
  status = WriteFileAtomicWith(
      path, [&](const std::string&) -> Status { throw std::runtime_error("boom"); });
  EXPECT_THAT(status.message(), StartsWith(path + ": "));
  EXPECT_THAT(status.message(), HasSubstr("boom"));
  EXPECT_EQ(testing::ReadText(path), "previous");
  EXPECT_EQ(CountEntries(dir), 1);
}

TEST(AtomicFileTest, TempFileIsBesideTheTargetWithItsExtension) {
  // Writers that choose the format by extension (cv::imwrite) work on the temp path.
  const std::string dir = testing::MakeTempDir("atomic");
  const std::string path = dir + "/image.png";
  std::string temp_seen;
  const cv::Mat image(4, 6, CV_8UC3, cv::Scalar(10, 20, 30));
  const Status status = WriteFileAtomicWith(path, [&](const std::string& temp) {
    temp_seen = temp;
    return cv::imwrite(temp, image) ? Status::Ok() : Status::Error(temp + ": imwrite failed");
  });
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(fs::path(temp_seen).parent_path(), fs::path(dir));
  EXPECT_EQ(fs::path(temp_seen).extension(), ".png");
  EXPECT_EQ(fs::path(temp_seen).filename().string()[0], '.');  // hidden
  const cv::Mat read = cv::imread(path);
  ASSERT_EQ(read.size(), image.size());
  EXPECT_EQ(cv::norm(read, image, cv::NORM_INF), 0);
}

TEST(AtomicFileTest, WriterThatWritesNothingFails) {
  const std::string dir = testing::MakeTempDir("atomic");
  const std::string path = dir + "/a.bin";
  const Status status = WriteFileAtomicWith(path, [](const std::string& temp) {
    fs::remove(temp);
    return Status::Ok();
  });
  EXPECT_EQ(status.message(), path + ": the writer produced no file");
  EXPECT_FALSE(fs::exists(path));
}

TEST(AtomicFileTest, ErrorsNameThePath) {
  const std::string dir = testing::MakeTempDir("atomic");
  Status status = WriteFileAtomic(dir + "/missing/a.txt", "x");
  EXPECT_THAT(status.message(), StartsWith(dir + "/missing/a.txt: "));
  status = WriteFileAtomic(dir, "x");
  EXPECT_EQ(status.message(), dir + ": is a folder, not a file");
  std::string contents;
  status = ReadFileToString(dir + "/none.txt", &contents);
  EXPECT_EQ(status.message(), dir + "/none.txt: no such file");
  status = ReadFileToString(dir, &contents);
  EXPECT_EQ(status.message(), dir + ": is a folder, not a file");
}

TEST(AtomicFileTest, MakeDirectories) {
  const std::string dir = testing::MakeTempDir("atomic");
  ASSERT_TRUE(MakeDirectories(dir + "/a/b/c").ok());
  EXPECT_TRUE(fs::is_directory(dir + "/a/b/c"));
  EXPECT_TRUE(MakeDirectories(dir + "/a/b/c").ok());  // already there
  ASSERT_TRUE(WriteFileAtomic(dir + "/file", "x").ok());
  Status status = MakeDirectories(dir + "/file");
  EXPECT_EQ(status.message(), dir + "/file: exists and is not a folder");
  status = MakeDirectories(dir + "/file/sub");
  EXPECT_THAT(status.message(), StartsWith(dir + "/file/sub: cannot create folder"));
}

// A staged folder replaces the target whole at Commit(), and only then; one dropped
// uncommitted leaves the target (and its parent) as it was, without the staging folder.
TEST(StagedFolderTest, ReplacesWholeOnCommitAndLeavesNothingOtherwise) {
  const std::string dir = testing::MakeTempDir("staged");
  const std::string target = dir + "/frames";
  fs::create_directories(target);
  ASSERT_TRUE(WriteFileAtomic(target + "/old.txt", "old").ok());
  {
    StagedFolder staged;  // dropped without Commit(): as if interrupted
    ASSERT_TRUE(staged.Open(target).ok());
    EXPECT_THAT(staged.path(), StartsWith(dir + "/.frames.partial-"));
    ASSERT_TRUE(WriteFileAtomic(staged.path() + "/new.txt", "new").ok());
    EXPECT_TRUE(fs::exists(target + "/old.txt"));
  }
  EXPECT_EQ(CountEntries(dir), 1);  // just frames/
  EXPECT_EQ(CountEntries(target), 1);
  {
    StagedFolder staged;
    ASSERT_TRUE(staged.Open(target).ok());
    ASSERT_TRUE(WriteFileAtomic(staged.path() + "/new.txt", "new").ok());
    ASSERT_TRUE(staged.Commit().ok());
  }
  EXPECT_EQ(CountEntries(dir), 1);
  EXPECT_FALSE(fs::exists(target + "/old.txt"));  // the earlier content went whole
  std::string text;
  ASSERT_TRUE(ReadFileToString(target + "/new.txt", &text).ok());
  EXPECT_EQ(text, "new");
  // A new target, and a stale staging folder left by a killed process.
  fs::create_directories(dir + "/.stages.partial-stale1");
  StagedFolder fresh;
  ASSERT_TRUE(fresh.Open(dir + "/stages").ok());
  EXPECT_FALSE(fs::exists(dir + "/.stages.partial-stale1"));
  ASSERT_TRUE(fresh.Commit().ok());
  EXPECT_TRUE(fs::is_directory(dir + "/stages"));
  EXPECT_EQ(CountEntries(dir), 2);
  EXPECT_FALSE(fresh.Commit().ok());  // once only
  // A file in the way is an error that names it.
  ASSERT_TRUE(WriteFileAtomic(dir + "/file", "x").ok());
  StagedFolder blocked;
  EXPECT_EQ(blocked.Open(dir + "/file").message(), dir + "/file: exists and is not a folder");
}

}  // namespace
}  // namespace fresco
