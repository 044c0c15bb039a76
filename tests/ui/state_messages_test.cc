// Messages true to the state, the app driven headless (issue 58, item 6): also "(unsaved)"
// after Ctrl+Z to the saved state, and a step's estimate at its end. Also there: a
// fold-over status line goes with its Undo (UiInput.GroupColoursStayAcrossEdits...) and
// undo says what it changed back (CameraAttach.*).
#include <chrono>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "tests/test_support.h"
#include "tests/ui/headless_ui.h"
#include "ui/core/job_estimate.h"

namespace fresco {
namespace {

using testing::HeadlessApp;
namespace fs = std::filesystem;

// A stage panel without a debug image says why, true to the worker's state (issue 58, item
// 6): never "they appear when paused" while paused with none shown.
TEST(StateMessages, AStagePanelSaysWhyItShowsNoDebugImage) {
  HeadlessApp app(testing::Capture() + "/project.json", 2);
  const std::string depth = "Stage: depth and visibility";
  ASSERT_TRUE(app.runner.Snapshot()->report_has_images) << "a sought frame is shown";
  EXPECT_NE(app.ReportOf(depth, "image"), "");
  EXPECT_EQ(app.ReportOf(depth, "note"), "");
  // Paused after playing: the last frame was painted between two publishes, without images.
  auto snap = std::make_shared<RunnerSnapshot>(*app.runner.Snapshot());
  for (StageReport& stage : snap->report.stages) stage.images.clear();
  snap->report_has_images = false;
  const auto note = [&] {
    app.ui.snapshot = snap;
    app.imgui.Frame(app.ui, app.panels, &app.input);
    return app.ReportOf(depth, "note");
  };
  EXPECT_EQ(note(), "(frame " + std::to_string(snap->report.frame) +
                        " was painted while playing, without debug images: Step or Apply (F5) "
                        "paints one with them)");
  snap->playing = true;
  EXPECT_EQ(note(), "(debug images appear when paused or stepping)");
  snap->playing = false;
  snap->report_has_images = true;
  EXPECT_EQ(note(), "(this stage drew no debug image for this frame)");
  // The real worker: played, then paused; whatever the last frame had, the note matches it.
  app.runner.Play();
  app.runner.Pause();
  app.runner.WaitIdle();
  app.Frames(2);
  const auto paused = app.runner.Snapshot();
  ASSERT_FALSE(paused->playing);
  EXPECT_EQ(app.ReportOf(depth, "note").find("appear when paused"), std::string::npos);
  if (paused->report_has_images) {
    EXPECT_NE(app.ReportOf(depth, "image"), "");
  }
}

// The calibration light is never green before the two-camera check has seen the views: not
// while the images are still being detected, not while the check runs; green after it.
TEST(StateMessages, TheCalibrationLightIsNotGreenBeforeTheOneCameraCheck) {
  FRESCO_REQUIRE_SHARED_DATA();
  const std::string dir = testing::MakeTempDir("ui-light") + "/left";
  fs::create_directories(dir);
  for (const auto& e :
       fs::directory_iterator(testing::SharedDataDir() + "/opencv-chessboard-stereo"))
    if (e.path().filename().string().rfind("left", 0) == 0 && e.path().extension() == ".jpg")
      fs::copy(e.path(), dir + "/" + e.path().filename().string());
  CalibrationRunner runner;
  testing::NullTextures textures;
  UiContext ui{nullptr, nullptr, &runner, &textures, nullptr, nullptr, false};
  testing::ImGuiHeadless imgui;
  std::unique_ptr<Panel> panel;
  for (auto& p : MakePanels())
    if (std::string(p->Title()) == kCalibrationPanelTitle) panel = std::move(p);
  ASSERT_TRUE(panel);
  calib::CalibrateRequest request;
  request.images_dir = dir;
  ASSERT_TRUE(calib::ParseBoardSpec("chessboard:9x6:0.025", "board", &request.board).ok());
  request.model = "opencv4";
  runner.Detect(request);
  // The panel drawn as the app draws it while the worker detects and checks.
  int detecting = 0, checking = 0;
  std::string green_while;  // the first status shown with a green light before the end
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(2);
  std::map<std::string, std::string> report;
  while (std::chrono::steady_clock::now() < deadline) {
    testing::ImGuiHeadless::DrawPanel(ui, *panel, ImVec2(900, 1400));
    report = panel->Report();
    const std::string& status = report["status"];
    if (status.rfind("detected", 0) == 0) break;
    const bool working = status.rfind("detecting", 0) == 0 || status.rfind("checking", 0) == 0;
    detecting += status.rfind("detecting", 0) == 0;
    checking += status.rfind("checking", 0) == 0;
    if (working && report["readiness"] == "green" && green_while.empty()) green_while = status;
  }
  EXPECT_EQ(green_while, "") << "green with " << report["views"] << " views";
  EXPECT_GT(detecting, 0);
  EXPECT_EQ(report["views"], "13");
  EXPECT_EQ(report["camera_doubts"], "0");
  EXPECT_EQ(report["readiness"], "green") << "after the check";
  std::printf("frames drawn while detecting %d, while checking %d\n", detecting, checking);
}

// The progress the joint pose adjustment publishes while the capture's project opens with
// it on, first to last.
// `first_at` (optional): when the first of them was published.
std::vector<std::shared_ptr<RunnerSnapshot>> AdjustingPoses(
    std::chrono::steady_clock::time_point* first_at = nullptr) {
  std::mutex mutex;
  std::vector<std::shared_ptr<RunnerSnapshot>> published;
  RunnerOptions options;
  options.publish_interval_ms = 0;
  options.on_publish = [&](const RunnerSnapshot& s) {
    std::lock_guard<std::mutex> lock(mutex);
    if (s.status.rfind("adjusting poses ", 0) != 0) return;
    if (published.empty() && first_at) *first_at = std::chrono::steady_clock::now();
    published.push_back(std::make_shared<RunnerSnapshot>(s));
  };
  AppState state;
  EXPECT_TRUE(state.Open(testing::Capture() + "/project.json").ok());
  state.project.pipeline.refine.joint = true;
  {
    PipelineRunner runner(options);
    runner.Restart(state.project);
    runner.WaitIdle();
  }
  EXPECT_FALSE(published.empty()) << "the joint adjustment published its progress";
  if (published.empty()) published.push_back(std::make_shared<RunnerSnapshot>());
  return published;
}

// A step of opening that goes quiet keeps counting its time in the window (status bar and
// Pipeline panel): the worker publishes only when the step says how far it got, and on the
// street under load the joint pose adjustment stood at "adjusting poses 120/246, 8 s elapsed,
// about 8 s left" for 34 s between its two passes, as if the app had hung.
TEST(StateMessages, AQuietStepOfOpeningKeepsCountingItsTime) {
  auto published = std::chrono::steady_clock::now();
  const auto adjusting = AdjustingPoses(&published).front();
  const std::string stem = adjusting->status.substr(0, adjusting->status.find(','));
  // The worker says nothing more for 3 s (as if the step were still under way).
  HeadlessApp app(testing::Capture() + "/project.json", 0);
  std::this_thread::sleep_until(published + std::chrono::seconds(3));
  app.ui.snapshot = adjusting;
  app.imgui.Frame(app.ui, app.panels, &app.input);
  const std::string line = app.ReportOf("Pipeline", "status");
  ASSERT_EQ(line.rfind(stem, 0), 0u) << "'" << line << "' for '" << adjusting->status << "'";
  const size_t seconds = line.find(" s elapsed");
  ASSERT_NE(seconds, std::string::npos) << line;
  const size_t number = line.rfind(' ', seconds - 1) + 1;
  EXPECT_GE(std::stoi(line.substr(number, seconds - number)), 3)
      << "the time stood still: '" << line << "' (published as '" << adjusting->status << "')";
}

// Ctrl+Z back to the saved state leaves nothing unsaved (the Project panel's "(unsaved)" and
// the status bar's "[unsaved]"), and Ctrl+Y away from it is unsaved again; after a Save, the
// state saved is the one compared with (before: unsaved after any undo or redo).
TEST(StateMessages, UndoBackToTheSavedStateIsNotUnsaved) {
  const std::string dir = testing::MakeTempDir("ui-unsaved");
  fs::copy(testing::Capture(), dir + "/capture", fs::copy_options::recursive);
  HeadlessApp app(dir + "/capture/project.json", 0);
  const int every = app.state.project.pipeline.update_every;
  const auto edit = [&](int update_every) {
    app.state.BeginEdit();
    app.state.project.pipeline.update_every = update_every;
    app.Frames(2);
  };
  ASSERT_FALSE(app.state.dirty);
  edit(every + 1);
  EXPECT_TRUE(app.state.dirty);
  app.CtrlTap('Z');
  EXPECT_EQ(app.state.project.pipeline.update_every, every);
  EXPECT_FALSE(app.state.dirty) << "back to the file's state, still '(unsaved)'";
  app.CtrlTap('Y');
  EXPECT_TRUE(app.state.dirty) << "the edit redone is not in the file";
  app.CtrlTap('S');
  EXPECT_FALSE(app.state.dirty);
  edit(every + 2);
  app.CtrlTap('Z');
  EXPECT_EQ(app.state.project.pipeline.update_every, every + 1);
  EXPECT_FALSE(app.state.dirty) << "back to the state saved with Ctrl+S";
  app.CtrlTap('Z');
  EXPECT_EQ(app.state.project.pipeline.update_every, every);
  EXPECT_TRUE(app.state.dirty) << "the file holds the edit undone";
}

// The progress line after the last step of the joint pose adjustment (done = total) while
// what follows it runs: never "about 0 s left" (it said so for as long as the rest took).
TEST(StateMessages, AStepAtItsEndSaysFinishingNotZeroSecondsLeft) {
  const auto last = AdjustingPoses().back();
  ASSERT_EQ(last->step_fraction, 1.0) << last->status;
  // Shown 5 s after the step began, as if what follows it were still under way.
  last->step_started = std::chrono::steady_clock::now() - std::chrono::seconds(5);
  HeadlessApp app(testing::Capture() + "/project.json", 0);
  app.ui.snapshot = last;
  app.imgui.Frame(app.ui, app.panels, &app.input);
  const std::string line = app.ReportOf("Pipeline", "status");
  EXPECT_EQ(line.find("0 s left"), std::string::npos) << line;
  EXPECT_NE(line.find("5 s elapsed, finishing"), std::string::npos) << line;
  EXPECT_EQ(ElapsedAndRemainingText(83.0, 0.999), "1:23 elapsed, finishing");  // 0.08 s left
  EXPECT_EQ(ElapsedAndRemainingText(83.0, 0.99), "1:23 elapsed, about 1 s left");
}

}  // namespace
}  // namespace fresco
