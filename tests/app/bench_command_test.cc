// `fresco bench` end to end on a small synthetic capture whose given poses carry 1 deg of
// noise: one row per combination of the swept settings, accuracy scored on held-out frames
// at the given poses and (the capture being synthetic) at the true poses, the Pareto front
// marked, and bad sweeps refused before anything runs.
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "tests/test_support.h"

namespace fresco::testing {
namespace {

namespace fs = std::filesystem;

class BenchCommandTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    capture_ = new std::string(MakeTempDir("bench-cli") + "/capture");
    const auto r = RunFresco({"synth", "--scene", "builtin:cube-room", "--out", *capture_,
                              "--frames", "20", "--size", "160x120", "--seed", "4",
                              "--pose-noise-deg", "1"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static void TearDownTestSuite() { delete capture_; }
  static std::string Project() { return *capture_ + "/project.json"; }
  static std::string* capture_;
};
std::string* BenchCommandTest::capture_ = nullptr;

TEST_F(BenchCommandTest, OneRowPerCombinationScoredOnHeldOutFrames) {
  const std::string out = MakeTempDir("bench-out") + "/out";
  const auto r = RunFresco({"bench", Project(), "--out", out, "--holdout", "5", "--sweep",
                            "pipeline.sampling=nearest,bilinear", "--sweep",
                            "pipeline.background.mode=off,robust"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("bench:"), std::string::npos) << "progress on stderr";
  const nlohmann::json rows = nlohmann::json::parse(ReadText(out + "/bench.json"));
  ASSERT_EQ(rows.size(), 5u);  // 2 x 2 and the naive baseline
  EXPECT_EQ(rows[4]["baseline"], "naive");
  int on_front = 0;
  for (const auto& row : rows) {
    EXPECT_EQ(row["settings"].size(), row.contains("baseline") ? 0u : 2u);
    EXPECT_EQ(row["holdout_frames"], 4);  // frames 2, 7, 12, 17 of 20
    EXPECT_EQ(row["frames_painted"], 16);
    EXPECT_GT(row["fps"].get<double>(), 0);
    EXPECT_TRUE(row["stage_ms"].contains(row.contains("baseline") ? "naive" : "warp"));
    EXPECT_GT(row["completeness"].get<double>(), 0.5);
    EXPECT_LE(row["completeness"].get<double>(), 1.0);
    // The held-out frames were rendered at the true poses: scored there, the painted model
    // agrees better than at the given (noisy) poses.
    ASSERT_TRUE(row.contains("truth"));
    EXPECT_GT(row["truth"]["psnr_db"].get<double>(), row["psnr_db"].get<double>() + 1.0);
    EXPECT_GT(row["truth"]["psnr_db"].get<double>(), 18.0);
    EXPECT_LT(row["one_minus_ncc"].get<double>(), 0.5);
    on_front += row.value("pareto", false);
  }
  EXPECT_GE(on_front, 1);
  const cv::Mat plot = cv::imread(out + "/pareto.png");
  EXPECT_FALSE(plot.empty());
}

TEST_F(BenchCommandTest, BadSweepsAreRefusedBeforeAnyRun) {
  const std::string out = MakeTempDir("bench-bad") + "/out";
  const auto no_values = RunFresco({"bench", Project(), "--out", out, "--sweep", "pipeline.sampling"});
  EXPECT_EQ(no_values.exit_code, 2);
  EXPECT_NE(no_values.err.find("pipeline.sampling"), std::string::npos) << no_values.err;
  const auto bad_key = RunFresco(
      {"bench", Project(), "--out", out, "--sweep", "pipeline.sampling=nearest,cubic"});
  EXPECT_EQ(bad_key.exit_code, 2);
  EXPECT_NE(bad_key.err.find("cubic"), std::string::npos) << bad_key.err;
  EXPECT_FALSE(fs::exists(out + "/bench.json"));
}

// A frame of another size than its camera: exit 2 naming the frame, as `fresco run` does (it
// used to crash bench).
TEST_F(BenchCommandTest, FrameOfTheWrongSizeExits2NamingIt) {
  const std::string dir = MakeTempDir("bench-frame-size") + "/capture";
  fs::copy(*capture_, dir, fs::copy_options::recursive);
  for (const auto& entry : fs::directory_iterator(dir + "/frames"))  // all: the video is
    cv::imwrite(entry.path().string(), cv::Mat(60, 80, CV_8UC3, cv::Scalar(1, 2, 3)));  // consistent
  const std::string out = MakeTempDir("bench-frame-size-out") + "/out";
  const auto r = RunFresco({"bench", dir + "/project.json", "--out", out, "--sweep",
                            "pipeline.sampling=nearest", "--no-baseline", "--quiet"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("' is 80x60 but the camera is 160x120"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out + "/bench.json"));
}

}  // namespace
}  // namespace fresco::testing
