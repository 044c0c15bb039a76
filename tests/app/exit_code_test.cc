// Exit codes come from a Status's kind, in one place (app/commands.h ExitCodeFor): bad input
// 2; an output that cannot be written, failed work and internal errors 1. The writers give
// their failures the output kind, so a verb whose output cannot be written exits 1 with one
// line naming the file, while bad input still exits 2.
#include <algorithm>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "app/commands.h"
#include "pipeline/core/atomic_file.h"
#include "pipeline/core/image_io.h"
#include "pipeline/core/status.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

using testing::MakeTempDir;
using testing::RunFresco;
using testing::WriteText;

TEST(ExitCodeFor, EachKindHasItsCode) {
  EXPECT_EQ(ExitCodeFor(Status::Ok()), kExitOk);
  EXPECT_EQ(ExitCodeFor(Status::Error("a.json: key: wrong")), kExitBadInput);
  EXPECT_EQ(ExitCodeFor(Status::OutputError("out/a.png: cannot write")), kExitFailure);
  EXPECT_EQ(ExitCodeFor(Status::Failed("no lens model could be solved")), kExitFailure);
  EXPECT_EQ(ExitCodeFor(Status::Internal("plan has 3 gains for 4 frames")), kExitFailure);
  EXPECT_EQ(kExitOk, 0);
  EXPECT_EQ(kExitFailure, 1);
  EXPECT_EQ(kExitBadInput, 2);
}

TEST(StatusKind, ErrorIsBadInputAndKindsSurviveAPrefix) {
  EXPECT_EQ(Status::Ok().kind(), StatusKind::kOk);
  EXPECT_EQ(Status::Error("x").kind(), StatusKind::kBadInput);
  const Status output = Status::OutputError("b.png: disk full");
  const Status prefixed = output.WithMessage("a: " + output.message());
  EXPECT_EQ(prefixed.kind(), StatusKind::kOutput);
  EXPECT_EQ(prefixed.message(), "a: b.png: disk full");
  EXPECT_TRUE(Status::Ok().WithMessage("x").ok());
}

TEST(StatusKind, ReclassifiedChangesOnlyBadInput) {
  EXPECT_EQ(Status::Error("x").Reclassified(StatusKind::kFailed).kind(), StatusKind::kFailed);
  EXPECT_EQ(Status::Error("x").Reclassified(StatusKind::kFailed).message(), "x");
  EXPECT_EQ(Status::OutputError("x").Reclassified(StatusKind::kFailed).kind(), StatusKind::kOutput);
  EXPECT_EQ(Status::Internal("x").Reclassified(StatusKind::kOutput).kind(), StatusKind::kInternal);
  EXPECT_TRUE(Status::Ok().Reclassified(StatusKind::kFailed).ok());
}

TEST(StatusKind, WritersFailWithOutputAndReadersWithBadInput) {
  const std::string dir = MakeTempDir("status-kinds");
  const std::string missing = dir + "/no/such/folder";
  EXPECT_EQ(WriteFileAtomic(missing + "/a.txt", "a").kind(), StatusKind::kOutput);
  EXPECT_EQ(WriteImageAtomic(missing + "/a.png", cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(9))).kind(),
            StatusKind::kOutput);
  // A writer callback that fails (here with the default kind) fails the write: output.
  const Status with = WriteFileAtomicWith(
      dir + "/b.txt", [](const std::string&) { return Status::Error("encoder refused"); });
  EXPECT_EQ(with.kind(), StatusKind::kOutput);
  EXPECT_FALSE(std::filesystem::exists(dir + "/b.txt"));
  WriteText(dir + "/file", "x");
  // An output folder that cannot be made is a bad argument (as before kinds: exit 2).
  EXPECT_EQ(MakeDirectories(dir + "/file").kind(), StatusKind::kBadInput);
  std::string text;
  EXPECT_EQ(ReadFileToString(missing + "/a.txt", &text).kind(), StatusKind::kBadInput);
}

// One "error: " line on stderr naming `path`.
void ExpectOneErrorLineNaming(const testing::CommandResult& r, const std::string& path) {
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(path), std::string::npos) << r.err;
}

TEST(ExitCodes, AnOutputIntoAMissingFolderExits1NamingTheFile) {
  const std::string out = MakeTempDir("exit-output") + "/no/such/folder/board.png";
  const auto r = RunFresco({"calib", "board", "chessboard:9x6:0.025", "--dpi", "72", "--out", out});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  ExpectOneErrorLineNaming(r, out);
}

TEST(ExitCodes, AnOutputFolderThatIsAFileExits2NamingIt) {
  const std::string out = MakeTempDir("exit-output-file") + "/views";
  WriteText(out, "not a folder");
  const auto r =
      RunFresco({"calib", "sample", "aprilgrid:6x6:0.088:0.3", "--views", "1", "--out", out});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  ExpectOneErrorLineNaming(r, out);
}

TEST(ExitCodes, BadInputStillExits2) {
  const std::string out = MakeTempDir("exit-bad-input") + "/board.png";
  const auto r = RunFresco({"calib", "board", "chessboard:9x6:-1", "--out", out});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  ExpectOneErrorLineNaming(r, "BOARD");
}

}  // namespace
}  // namespace fresco
