// One camera per calibration folder: image exclusion (names and globs), the image-size
// check, the split test on a real stereo pair's left and right images mixed in one folder
// (opencv-chessboard-stereo; skipped when ../shared/data is absent), and the "enough data"
// light that a mixed folder keeps off green.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "calib/calibrate.h"
#include "calib/camera_consistency.h"
#include "tests/calib/synthetic_boards.h"

namespace fresco::calib::testing {
namespace {

namespace fs = std::filesystem;

std::string StereoDir() {
  const fs::path dir = fs::path(FRESCO_ONE_CAMERA_SHARED_DATA) / "opencv-chessboard-stereo";
  return fs::is_directory(dir) ? dir.string() : std::string();
}

// A folder of links to the stereo images whose names start with one of `prefixes`.
std::string LinkImages(const std::string& tag, const std::vector<std::string>& prefixes) {
  const fs::path dir = fs::temp_directory_path() / ("fresco_one_camera_" + tag);
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const auto& entry : fs::directory_iterator(StereoDir())) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() != ".jpg") continue;
    for (const std::string& p : prefixes)
      if (name.rfind(p, 0) == 0) fs::create_symlink(entry.path(), dir / name);
  }
  return dir.string();
}

CalibrateRequest Request(const std::string& dir) {
  CalibrateRequest request;
  request.images_dir = dir;
  request.board = Spec("chessboard:9x6:0.025");
  request.model = "opencv4";
  request.cross_validate = false;
  return request;
}

CalibrationRun Calibrate(const std::string& dir, const std::vector<std::string>& exclude) {
  CalibrateRequest request = Request(dir);
  request.exclude = exclude;
  CalibrationRun run;
  Status s = DetectViews(request, &run);
  EXPECT_TRUE(s.ok()) << s.message();
  if (s.ok()) s = SolveViews(request, &run);
  EXPECT_TRUE(s.ok()) << s.message();
  return run;
}

TEST(ExcludeTest, NamesAndGlobs) {
  EXPECT_TRUE(IsExcluded("right03.jpg", {"right*.jpg"}));
  EXPECT_TRUE(IsExcluded("left07.jpg", {"x.png", "left07.jpg"}));
  EXPECT_TRUE(IsExcluded("left07.jpg", {"left0?.jpg"}));
  EXPECT_FALSE(IsExcluded("left07.jpg", {"right*", "left1*"}));
  EXPECT_FALSE(IsExcluded("left07.jpg", {}));
}

TEST(OneCameraTest, TwoImageSizesAreADoubtAndKeepTheLightOffGreen) {
  const BoardSpec spec = Spec("chessboard:9x6:0.025");
  SyntheticCapture capture;
  capture.views = 14;
  CalibrationRun run;
  run.width = capture.width;
  run.height = capture.height;
  run.views = SyntheticViews(spec, capture);
  ASSERT_TRUE(SeedCalibration(run.views, spec, run.width, run.height, &run.seed).ok());
  const DataReadiness clean = AssessReadiness(run.views, run.width, run.height, &run.seed);
  ASSERT_EQ(clean.level, DataReadiness::Level::kGreen);
  run.image_sizes = {{"640x480", 14}};
  EXPECT_TRUE(ImageSizeDoubts(run).empty());
  run.image_sizes["1280x720"] = 5;
  const std::vector<std::string> doubts = ImageSizeDoubts(run);
  ASSERT_EQ(doubts.size(), 1u);
  EXPECT_NE(doubts[0].find("1280x720: 5"), std::string::npos) << doubts[0];
  EXPECT_NE(doubts[0].find("different cameras"), std::string::npos) << doubts[0];
  const DataReadiness mixed = AssessReadiness(run.views, run.width, run.height, &run.seed, doubts);
  EXPECT_EQ(mixed.level, DataReadiness::Level::kYellow);
  EXPECT_EQ(mixed.reasons.back(), doubts[0]);
}

// Two cameras of one image size (a stereo pair: focal lengths 600 and 660 px, principal
// points 30 px apart), 14 views each, in one folder: the split test before any solve finds
// them, and the "enough data" light stays off green from detection on; one camera's 28 views
// raise no doubt.
TEST(OneCameraTest, TwoCamerasOfOneSizeAreFoundBeforeSolving) {
  const BoardSpec spec = Spec("chessboard:9x6:0.025");
  const auto views_of = [&](const std::string& stem, std::vector<double> intrinsics,
                            unsigned seed) {
    SyntheticCapture capture;
    capture.views = 14;
    capture.intrinsics = std::move(intrinsics);
    capture.seed = seed;
    std::vector<BoardView> views = SyntheticViews(spec, capture);
    for (size_t i = 0; i < views.size(); ++i) {
      char name[32];
      std::snprintf(name, sizeof(name), "%s%02zu.png", stem.c_str(), i + 1);
      views[i].name = name;
    }
    return views;
  };
  CalibrateRequest request;
  request.board = spec;
  CalibrationRun mixed;
  mixed.width = 640;
  mixed.height = 480;
  mixed.image_sizes = {{"640x480", 28}};
  mixed.views = views_of("left", {600, 605, 322, 238}, 7);
  for (BoardView& v : views_of("right", {660, 665, 292, 250}, 8)) mixed.views.push_back(v);
  CheckOneCameraBeforeSolving(request, &mixed);
  ASSERT_FALSE(mixed.split_tests.empty());
  for (const SplitTest& t : mixed.split_tests)
    std::printf("two cameras: %s: ratio %.2f\n", t.how.c_str(), t.ratio);
  EXPECT_EQ(mixed.split_tests[0].how, "file names left* / right*");
  ASSERT_FALSE(mixed.camera_doubts.empty());
  EXPECT_NE(mixed.camera_doubts[0].find("look like two cameras"), std::string::npos);
  CalibrationSeed seed;
  ASSERT_TRUE(SeedCalibration(mixed.views, spec, 640, 480, &seed).ok());
  EXPECT_NE(AssessReadiness(mixed.views, 640, 480, &seed, mixed.camera_doubts).level,
            DataReadiness::Level::kGreen);

  CalibrationRun one = mixed;
  one.views = views_of("left", {600, 605, 322, 238}, 7);
  for (BoardView& v : views_of("right", {600, 605, 322, 238}, 8)) one.views.push_back(v);
  CheckOneCameraBeforeSolving(request, &one);
  for (const SplitTest& t : one.split_tests) {
    std::printf("one camera: %s: ratio %.2f\n", t.how.c_str(), t.ratio);
    EXPECT_LT(t.ratio, kSplitSigmaRatio) << t.how;
  }
  EXPECT_TRUE(one.camera_doubts.empty());
}

TEST(OneCameraRealDataTest, MixedLeftAndRightImagesAreFlaggedAndExclusionFixesIt) {
  if (StereoDir().empty())
    GTEST_SKIP() << "../shared/data/opencv-chessboard-stereo is absent: real-data check skipped";
  const CalibrationRun mixed = Calibrate(LinkImages("mixed", {"left", "right"}), {});
  ASSERT_FALSE(mixed.split_tests.empty());
  for (const SplitTest& t : mixed.split_tests)
    std::printf("mixed: %s: joint %.3f px, split %.3f px, ratio %.3f\n", t.how.c_str(),
                t.joint_sigma_px, t.split_sigma_px, t.ratio);
  EXPECT_EQ(mixed.split_tests[0].how, "file names left* / right*");
  EXPECT_GT(mixed.split_tests[0].ratio, kSplitSigmaRatio);
  ASSERT_FALSE(mixed.camera_doubts.empty());
  EXPECT_NE(AllWarnings(mixed).find("look like two cameras"), std::string::npos);
  EXPECT_NE(
      AssessReadiness(mixed.views, mixed.width, mixed.height, &mixed.seed, mixed.camera_doubts)
          .level,
      DataReadiness::Level::kGreen);
  // Found before solving too (right after detection, as the app's light shows it).
  CalibrationRun detected = mixed;
  detected.choice = {};
  CheckOneCameraBeforeSolving(Request(""), &detected);
  ASSERT_FALSE(detected.split_tests.empty());
  std::printf("mixed, before solving: ratio %.3f\n", detected.split_tests[0].ratio);
  EXPECT_FALSE(detected.camera_doubts.empty());

  // The same folder with the right camera's images excluded: one camera, no doubt.
  const CalibrationRun left = Calibrate(LinkImages("mixed", {"left", "right"}), {"right*"});
  EXPECT_EQ(left.excluded.size(), 13u);
  EXPECT_EQ(left.views.size(), 13u);
  for (const SplitTest& t : left.split_tests) {
    std::printf("left only: %s: ratio %.3f\n", t.how.c_str(), t.ratio);
    EXPECT_LT(t.ratio, kSplitSigmaRatio) << t.how;
  }
  EXPECT_TRUE(left.camera_doubts.empty()) << AllWarnings(left);
}

}  // namespace
}  // namespace fresco::calib::testing
