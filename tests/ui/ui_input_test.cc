// The app driven headless by mouse and key events, frame by frame, over a real painting
// worker: orbiting the 3D view never moves its window, title bars stay below the menu bar,
// debug images zoom and read pixels, group colours stay put across grouping edits, a
// missing video is one error, the seek slider, step back and F5 keep the frame, and a key
// tap or a drag shorter than a frame still arrives (input_queue.h), and New project makes,
// saves and opens a project or shows the command line's error and writes nothing, the
// Project panel repairs a project whose video moved (or edits the open one's paths, undoably),
// and dropped files fill the New project form or the path editor, or open a project.
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>

#include <gtest/gtest.h>
#include <imgui.h>
#include <imgui_internal.h>

#include "tests/test_support.h"
#include "tests/ui/headless_ui.h"
#include "ui/core/app_frame.h"
#include "ui/core/calibration_runner.h"
#include "ui/core/dropped_file.h"
#include "ui/core/group_colour.h"
#include "ui/core/image_view.h"
#include "ui/core/input_queue.h"
#include "ui/core/project_paths.h"
#include "ui/panels/panels.h"
#include "ui/panels/path_field.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using testing::Activate;
using testing::Capture;
using testing::ImGuiHeadless;
using testing::MakeTempDir;
using testing::NullTextures;
using testing::NullViewport;
using testing::SourceDir;
using testing::TypeInto;

constexpr int kKeyF5 = 294, kKeyLeft = 263, kKeyRight = 262;  // GLFW's codes

// The whole app headless on a copy of the capture, paused at `frame`.
std::string CopyOfCapture() {
  const std::string dir = MakeTempDir("ui-input");
  fs::copy(Capture(), dir + "/capture", fs::copy_options::recursive);
  return dir;
}

struct App : testing::HeadlessApp {
  explicit App(int frame) : App(CopyOfCapture(), frame) {}
  App(const std::string& copy, int frame) : HeadlessApp(copy + "/capture/project.json", frame) {
    dir = copy;
  }
  void Tap(int key) {
    input.keys_down[key] = true;
    Frame();
    input.keys_down[key] = false;
    Frame();
  }
  std::string dir;
};

std::vector<float> Numbers(const std::string& text) {
  std::istringstream in(text);
  std::vector<float> v;
  for (float x; in >> x;) v.push_back(x);
  return v;
}

float Yaw(App& app) {
  const auto v = Numbers(app.ReportOf("3D view", "yaw pitch distance"));
  return v.empty() ? -1e9f : v[0];
}

// A point in the 3D view's image (below its two rows of controls).
ImVec2 InsideThe3DView() {
  ImGuiWindow* w = App::Window("3D view");
  return ImVec2(w->Pos.x + 0.5f * w->Size.x, w->Pos.y + 0.7f * w->Size.y);
}

TEST(UiInput, DraggingThe3DViewOrbitsAndNeverMovesTheWindow) {
  App app(3);
  const ImVec2 pos = App::Window("3D view")->Pos;
  const float yaw = Yaw(app);
  const ImVec2 from = InsideThe3DView();
  app.Drag(from, ImVec2(from.x + 60, from.y), 6);  // 10 px per frame
  EXPECT_EQ(App::Window("3D view")->Pos.x, pos.x);
  EXPECT_EQ(App::Window("3D view")->Pos.y, pos.y);
  EXPECT_NEAR(Yaw(app), yaw - 0.4f * 60, 1e-3);  // 0.4 degrees per pixel
  // Dragging on past the view's edge keeps orbiting (the view holds the mouse).
  app.Drag(from, ImVec2(from.x, from.y - 400), 8);
  EXPECT_EQ(App::Window("3D view")->Pos.y, pos.y);
  EXPECT_NEAR(Yaw(app), yaw - 0.4f * 60, 1e-3);
  const std::vector<float> view = Numbers(app.ReportOf("3D view", "yaw pitch distance"));
  ASSERT_EQ(view.size(), 3u);
  EXPECT_EQ(view[1], -89.0f);  // pitch, clamped
}

// Every panel is tiled, the tools too: dragging a title bar (up past the menu bar, or
// anywhere) leaves the tile where it was.
TEST(UiInput, TiledPanelsNeverMoveNorGoUnderTheMenuBar) {
  App app(0);
  app.Find(kCalibrationPanelTitle).open = true;  // a tool: a tab below the 3D view
  app.Frames(2);
  for (const char* title : {kCalibrationPanelTitle, "3D view"}) {
    ImGuiWindow* window = App::Window(title);
    const ImVec2 pos = window->Pos;
    EXPECT_GE(pos.y, ImGui::GetFrameHeight()) << title;
    app.Drag(ImVec2(pos.x + 60, pos.y + 5), ImVec2(pos.x + 200, 0), 5);
    EXPECT_EQ(window->Pos.x, pos.x) << title;
    EXPECT_EQ(window->Pos.y, pos.y) << title;
  }
}

TEST(UiInput, StageImageStartsOnTheLargestZoomsAndReadsPixels) {
  App app(5);
  const std::string title = "Stage: warp to buffer";
  const auto snap = app.runner.Snapshot();
  const StageReport* warp = snap->report.Stage("warp");
  ASSERT_NE(warp, nullptr);
  std::string largest;
  size_t largest_area = 0;
  int warped = 0;
  for (const auto& [name, image] : warp->images)
    if (name.rfind("warped", 0) == 0 && (++warped, image.total() > largest_area))
      largest = name, largest_area = image.total();
  ASSERT_GE(warped, 2) << "several buffers seen";
  EXPECT_EQ(app.ReportOf(title, "image"), largest);
  const cv::Mat& image = warp->images.at(largest);
  const std::vector<float> view = Numbers(app.ReportOf(title, "view"));
  ASSERT_EQ(view.size(), 4u);
  EXPECT_NEAR(view[3] / view[2], static_cast<float>(image.rows) / image.cols, 0.02);
  // The readout names the pixel under the cursor and its value.
  // Whole pixels: ImGui floors the mouse position.
  const float mx = std::floor(view[0] + 0.3f * view[2]), my = std::floor(view[1] + 0.6f * view[3]);
  app.MouseTo(mx, my);
  app.Frames(2);
  ASSERT_EQ(Numbers(app.ReportOf(title, "view")), view) << "the view moved";
  const int col = static_cast<int>((mx - view[0]) / view[2] * image.cols);
  const int row = static_cast<int>((my - view[1]) / view[3] * image.rows);
  EXPECT_EQ(app.ReportOf(title, "pixel"), DescribePixel(image, col, row));
  EXPECT_EQ(app.ReportOf(title, "zoom"), "1.000");
  // The wheel zooms about the cursor: the same pixel stays under it.
  ImGui::GetIO().MouseWheel = 2;
  app.Frame();
  EXPECT_EQ(app.ReportOf(title, "zoom"), "1.562");
  EXPECT_EQ(app.ReportOf(title, "pixel"), DescribePixel(image, col, row));
  const ImVec2 window_pos = App::Window(title)->Pos;
  // A drag pans (and does not move the window): another pixel comes under the cursor.
  app.Drag(ImVec2(mx, my), ImVec2(mx - 40, my), 4);
  EXPECT_EQ(App::Window(title)->Pos.x, window_pos.x);
  app.MouseTo(mx, my);
  app.Frame();
  EXPECT_NE(app.ReportOf(title, "pixel"), DescribePixel(image, col, row));
  EXPECT_FALSE(app.ReportOf(title, "pixel").empty());
}

TEST(UiInput, FalseColouredImagesShowTheirScale) {
  App app(5);
  EXPECT_FALSE(app.ReportOf("Stage: depth and visibility", "legend").empty())
      << "the depth image is false-coloured";
  EXPECT_TRUE(app.ReportOf("Stage: warp to buffer", "legend").empty());
  EXPECT_NE(app.ReportOf("Misalignment", "legend").find("grey levels"), std::string::npos);
}

TEST(UiInput, PaintedBuffersStartOnTheLargestBuffer) {
  App app(5);
  const auto& texels = app.runner.Snapshot()->geometry->buffer_texels;
  const int largest =
      static_cast<int>(std::max_element(texels.begin(), texels.end()) - texels.begin());
  EXPECT_EQ(app.ReportOf("Painted buffers", "buffer"), std::to_string(largest));
}

std::set<std::string> Tokens(const std::string& text) {
  std::istringstream in(text);
  std::set<std::string> s;
  for (std::string t; in >> t;) s.insert(t);
  return s;
}

TEST(UiInput, GroupColoursStayAcrossEditsAndASplitBackIsExplained) {
  App app(2);
  const std::set<std::string> before = Tokens(app.ReportOf("Grouping", "colours"));
  ASSERT_EQ(before.size(), 6u);  // the cube room's six walls
  // Merge group 0 with each other wall until one merge holds (walls at right angles share
  // a plane's projection) and one is split back (opposite walls fold over).
  bool held = false, split = false;
  for (int other = 1; other < 6 && !(held && split); ++other) {
    app.state.Undo();  // back to the automatic groups
    app.state.project.grouping.groups.clear();
    ApplyProject(app.ui);
    app.runner.WaitIdle();
    app.Frames(1);
    testing::MergeAndApply(app, 0, other);
    const std::set<std::string> after = Tokens(app.ReportOf("Grouping", "colours"));
    const std::string message = app.ReportOf("Grouping", "split");
    if (after.size() == 5u) {
      held = true;
      EXPECT_EQ(message, "");
      // Four walls untouched: their colours are as before; the merged one keeps one colour.
      int kept = 0;
      for (const std::string& t : after) kept += before.count(t) > 0;
      EXPECT_EQ(kept, 5) << app.ReportOf("Grouping", "colours");
    } else {
      split = true;
      EXPECT_EQ(after, before) << "split back: every wall in its old colour";
      EXPECT_NE(message.find("split back apart"), std::string::npos) << message;
      EXPECT_NE(app.state.message.find("split back apart"), std::string::npos) << app.state.message;
      // Ctrl+Z: the status line goes with the merge it described (issue 58, item 6).
      app.CtrlTap('Z');
      EXPECT_EQ(app.state.message, "undone: the grouping");
      app.runner.WaitIdle();
      app.Frames(2);
      EXPECT_EQ(app.ReportOf("Grouping", "split"), "");
      EXPECT_EQ(app.state.message, "undone: the grouping");
    }
    EXPECT_EQ(app.runner.Snapshot()->frame, 2) << "the edit kept the frame";
  }
  EXPECT_TRUE(held);
  EXPECT_TRUE(split);
}

TEST(UiInput, AMissingVideoIsOneErrorAndNotARecentProject) {
  App app(0);
  const std::string bad = app.dir + "/broken/project.json";
  fs::copy(app.dir + "/capture", app.dir + "/broken", fs::copy_options::recursive);
  fs::remove_all(app.dir + "/broken/frames");
  AppState fresh;
  const Status s = fresh.Open(bad);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("video"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("frames"), std::string::npos) << s.message();
  EXPECT_TRUE(fresh.recent.empty());
  // Through the File menu's path: an error in the status bar, the open project unchanged.
  const std::string before = app.state.project.file_path;
  RequestOpen(app.ui, bad);
  app.Frame();
  EXPECT_EQ(app.state.message.rfind("error: ", 0), 0u) << app.state.message;
  EXPECT_EQ(app.state.message.find("opened"), std::string::npos) << app.state.message;
  EXPECT_EQ(app.state.project.file_path, before);
  EXPECT_EQ(std::count(app.state.recent.begin(), app.state.recent.end(), bad), 0);
}

TEST(UiInput, AProjectTheWorkerCannotReadIsOneErrorAndLeavesTheRecentList) {
  App app(0);
  const std::string bad = app.dir + "/broken/project.json";
  fs::copy(app.dir + "/capture", app.dir + "/broken", fs::copy_options::recursive);
  {
    std::ofstream poses(app.dir + "/broken/sparse/images.txt");
    poses << "1 not a pose line\n";
  }
  RequestOpen(app.ui, bad);
  app.Frame();  // opened: the files are there
  EXPECT_EQ(app.state.message.rfind("opened ", 0), 0u) << app.state.message;
  app.runner.WaitIdle();
  app.Frames(2);
  EXPECT_EQ(app.state.message.rfind("error: ", 0), 0u) << app.state.message;
  EXPECT_NE(app.state.message.find("images.txt"), std::string::npos) << app.state.message;
  EXPECT_EQ(std::count(app.state.recent.begin(), app.state.recent.end(), bad), 0);
  // A good project after it opens, stays in the list and says so.
  RequestOpen(app.ui, app.dir + "/capture/project.json");
  app.Frame();
  app.runner.WaitIdle();
  app.Frames(2);
  EXPECT_EQ(app.state.message.rfind("opened ", 0), 0u) << app.state.message;
  EXPECT_EQ(app.state.recent.front(), app.dir + "/capture/project.json");
}

TEST(UiInput, SeekSliderKeepsTheReleasedFrame) {
  App app(9);
  const std::vector<float> slider = Numbers(app.ReportOf("Pipeline", "seek slider"));
  ASSERT_EQ(slider.size(), 4u);
  ASSERT_GT(slider[2], 50);
  const float y = slider[1] + 0.5f * slider[3];
  // Press near the left end and drag to about a third of the way.
  app.MouseTo(slider[0] + 4, y);
  app.Frames(2);
  app.input.mouse_down[0] = true;
  app.Frame();
  app.MouseTo(slider[0] + 0.3f * slider[2], y);
  app.Frame();
  const std::string dragged = app.ReportOf("Pipeline", "seek");
  ASSERT_NE(dragged, "9");
  app.input.mouse_down[0] = false;
  app.Frame();
  app.Frame();
  EXPECT_EQ(app.ReportOf("Pipeline", "seek"), dragged) << "snapped back on release";
  app.runner.WaitIdle();
  app.Frames(2);
  EXPECT_EQ(std::to_string(app.runner.Snapshot()->frame), dragged);
  EXPECT_EQ(app.runner.Snapshot()->seek_target, -1);
  EXPECT_EQ(app.ReportOf("Pipeline", "seek"), dragged);
}

TEST(UiInput, ArrowsStepBackAndForwardAndF5KeepsTheFrame) {
  App app(5);
  app.Tap(kKeyLeft);
  app.runner.WaitIdle();
  EXPECT_EQ(app.runner.Snapshot()->frame, 4);
  app.Frame();
  app.Tap(kKeyRight);
  app.runner.WaitIdle();
  EXPECT_EQ(app.runner.Snapshot()->frame, 5);
  // F5 applies an edit and repaints up to the frame being looked at.
  app.Frame();
  const uint64_t geometry = app.runner.Snapshot()->geometry_version;
  app.state.BeginEdit();
  app.state.project.pipeline.update_every = 2;
  app.Tap(kKeyF5);
  app.runner.WaitIdle();
  EXPECT_GT(app.runner.Snapshot()->geometry_version, geometry) << "F5 did not apply";
  EXPECT_EQ(app.runner.Snapshot()->frame, 5);
  // At the first frame too (frame 0 is a frame to come back to, not "nothing painted").
  app.runner.Seek(0);
  app.runner.WaitIdle();
  app.Frame();
  app.Tap(kKeyF5);
  app.runner.WaitIdle();
  EXPECT_EQ(app.runner.Snapshot()->frame, 0);
}

// Step back (the Left key) paints on from the nearest painting state saved on the way (every
// 10 frames by default), not from frame 0, and paints what painting straight there paints.
TEST(UiInput, StepBackPaintsOnFromTheNearestSavedState) {
  App app(11);  // states saved before frames 0 and 10
  app.Tap(kKeyLeft);
  app.runner.WaitIdle();
  std::shared_ptr<const RunnerSnapshot> back = app.runner.Snapshot();
  EXPECT_EQ(back->frame, 10);
  EXPECT_EQ(back->seek_from, 10) << "painted again from frame " << back->seek_from;
  EXPECT_EQ(back->run.frames, 11);
  AppState state;
  ASSERT_TRUE(state.Open(app.dir + "/capture/project.json").ok());
  PipelineRunner straight;
  straight.Restart(state.project);
  straight.Seek(10);
  straight.WaitIdle();
  std::shared_ptr<const RunnerSnapshot> there = straight.Snapshot();
  ASSERT_TRUE(back->painted && there->painted);
  ASSERT_EQ(back->painted->size(), there->painted->size());
  for (size_t b = 0; b < back->painted->size(); ++b)
    EXPECT_EQ(cv::norm((*back->painted)[b], (*there->painted)[b], cv::NORM_INF), 0) << b;
  EXPECT_EQ(back->run.frames_painted, there->run.frames_painted);
  EXPECT_EQ(back->frames_painted, there->frames_painted) << "the per-frame history";
  // Once more: frame 9 lies before the state at 10, so from the one before frame 0.
  app.Frame();
  app.Tap(kKeyLeft);
  app.runner.WaitIdle();
  EXPECT_EQ(app.runner.Snapshot()->frame, 9);
  EXPECT_EQ(app.runner.Snapshot()->seek_from, 0);
}

// Seeking back repaints from the nearest saved state (here the one before frame 0): every
// snapshot the worker publishes meanwhile says where the seek goes and how far it got, never
// a bare "frame -1".
// A long step before painting (here the joint adjustment of the poses) says, beside how far
// it got, how long it has run and, once that can be told, about how long is left.
TEST(UiInput, TheStepsBeforePaintingSayTheTimeElapsedAndLeft) {
  std::mutex mutex;
  std::vector<std::string> statuses;
  RunnerOptions options;
  options.on_publish = [&](const RunnerSnapshot& s) {
    std::lock_guard<std::mutex> lock(mutex);
    statuses.push_back(s.status);
  };
  AppState state;
  ASSERT_TRUE(state.Open(Capture() + "/project.json").ok());
  state.project.pipeline.refine.joint = true;
  PipelineRunner runner(options);
  runner.Restart(state.project);
  runner.WaitIdle();
  std::lock_guard<std::mutex> lock(mutex);
  int adjusting = 0, reading = 0, loading = 0;
  for (const std::string& status : statuses) {
    loading += status.rfind("loading the scene, poses and buffers", 0) == 0;
    // The pre-pass's reading of every frame: how far, the time elapsed (and left).
    if (status.rfind("reading every frame ", 0) == 0) {
      ++reading;
      EXPECT_NE(status.find("/12, "), std::string::npos) << status;
      EXPECT_NE(status.find(" elapsed"), std::string::npos) << status;
    }
    if (status.rfind("adjusting poses ", 0) != 0) continue;
    ++adjusting;
    EXPECT_NE(status.find(" elapsed"), std::string::npos) << status;
  }
  EXPECT_GT(adjusting, 0) << "the joint adjustment published its progress";
  EXPECT_GT(reading, 0) << "the pre-pass's reading published its progress";
  EXPECT_EQ(loading, 1) << "the load said what it does";
}

TEST(UiInput, SeekingBackPublishesItsProgress) {
  struct Seen {
    int seek_target, frame;
    std::string status;
  };
  std::mutex mutex;
  std::vector<Seen> seen;
  RunnerOptions options;
  options.publish_interval_ms = 0;  // publish after every frame painted
  options.on_publish = [&](const RunnerSnapshot& s) {
    std::lock_guard<std::mutex> lock(mutex);
    seen.push_back({s.seek_target, s.frame, s.status});
  };
  AppState state;
  ASSERT_TRUE(state.Open(Capture() + "/project.json").ok());
  PipelineRunner runner(options);
  runner.Restart(state.project);
  runner.Seek(9);
  runner.WaitIdle();
  {
    std::lock_guard<std::mutex> lock(mutex);
    seen.clear();
  }
  runner.Seek(6);
  runner.WaitIdle();
  std::lock_guard<std::mutex> lock(mutex);
  ASSERT_GE(seen.size(), 3u);
  EXPECT_EQ(seen.front().seek_target, 6) << "the seek is announced first";
  EXPECT_EQ(seen.front().frame, -1);
  EXPECT_EQ(seen.front().status, "seeking");
  int last_frame = -1;
  for (size_t i = 0; i + 1 < seen.size(); ++i) {
    EXPECT_EQ(seen[i].seek_target, 6) << i;
    EXPECT_EQ(seen[i].status.rfind("seeking", 0), 0u) << i << ": " << seen[i].status;
    EXPECT_GE(seen[i].frame, last_frame) << i;
    last_frame = seen[i].frame;
  }
  EXPECT_GE(seen.size(), 6u) << "progress while frames 0..5 are repainted";
  EXPECT_EQ(seen.back().seek_target, -1);
  EXPECT_EQ(seen.back().frame, 6);
  EXPECT_EQ(seen.back().status, "paused");
}

// A step back says where it goes back from as it starts: the saved state it restores, not
// "reopening" (which it says only where no state is kept, as with no memory for them).
TEST(UiInput, AStepBackNamesTheSavedStateItGoesBackToNotAReopening) {
  std::mutex mutex;
  std::vector<std::string> labels;
  RunnerOptions options;
  options.on_publish = [&](const RunnerSnapshot& s) {
    std::lock_guard<std::mutex> lock(mutex);
    if (s.seek_target >= 0) labels.push_back(FrameLabel(s));
  };
  AppState state;
  ASSERT_TRUE(state.Open(Capture() + "/project.json").ok());
  for (const int budget_mb : {1024, 0}) {
    options.snapshot_budget_mb = budget_mb;
    PipelineRunner runner(options);
    runner.Restart(state.project);
    runner.Seek(11);  // states saved before frames 0 and 10
    runner.WaitIdle();
    {
      std::lock_guard<std::mutex> lock(mutex);
      labels.clear();
    }
    runner.Seek(10);  // a step back from frame 11
    runner.WaitIdle();
    std::lock_guard<std::mutex> lock(mutex);
    ASSERT_FALSE(labels.empty());
    EXPECT_EQ(labels.front(), budget_mb > 0
                                  ? "seeking to frame 10: from the state saved before frame 10"
                                  : "seeking to frame 10: reopening");
  }
}

// A seek can be stopped (Pause, the panel's Stop): it ends at the last frame it painted,
// paused, with no seek under way.
TEST(SeekProgress, PauseStopsASeekWhereItGotTo) {
  PipelineRunner* runner_ptr = nullptr;
  std::atomic<bool> paused{false};
  RunnerOptions options;
  options.publish_interval_ms = 0;  // publish after every frame painted
  options.on_publish = [&](const RunnerSnapshot& s) {
    // The worker itself asks to stop once the seek painted frame 2.
    if (s.seek_target == 9 && s.frame >= 2 && !paused.exchange(true)) runner_ptr->Pause();
  };
  AppState state;
  ASSERT_TRUE(state.Open(Capture() + "/project.json").ok());
  PipelineRunner runner(options);
  runner_ptr = &runner;
  runner.Restart(state.project);
  runner.Seek(9);
  runner.WaitIdle();
  const auto snap = runner.Snapshot();
  EXPECT_TRUE(paused);
  EXPECT_EQ(snap->seek_target, -1);
  EXPECT_GE(snap->frame, 2);
  EXPECT_LT(snap->frame, 9);
  EXPECT_EQ(snap->status, "paused");
}

TEST(UiInput, SeekProgressIsNamedNotFrameMinusOne) {
  RunnerSnapshot snap;
  snap.seek_target = 40;
  EXPECT_EQ(FrameLabel(snap), "seeking to frame 40: reopening");
  snap.seek_state = 30;
  EXPECT_EQ(FrameLabel(snap), "seeking to frame 40: from the state saved before frame 30");
  snap.frame = 17;
  EXPECT_EQ(FrameLabel(snap), "seeking to frame 40: at 17");
  snap.seek_target = -1;
  EXPECT_EQ(FrameLabel(snap), "frame 17");
  snap.frame = -1;
  EXPECT_EQ(FrameLabel(snap), "no frame painted yet");
}

TEST(UiInput, AKeyTapWithinOneFrameIsStillSeen) {
  App app(1);
  app.state.BeginEdit();  // something to save
  app.state.project.pipeline.update_every = 3;
  ASSERT_TRUE(app.state.dirty);
  app.CtrlTap('S');  // pressed and released between two frames
  EXPECT_FALSE(app.state.dirty) << "Ctrl+S was lost";
  EXPECT_EQ(app.state.message.rfind("saved ", 0), 0u) << app.state.message;
}

TEST(UiInput, ADragWithinOneFrameStillOrbits) {
  App app(1);
  const float yaw = Yaw(app);
  const ImVec2 p = InsideThe3DView();
  InputQueue queue;
  auto push = [&](InputEvent::Kind kind, float x, float y, bool down) {
    InputEvent e;
    e.kind = kind;
    e.x = x, e.y = y, e.down = down;
    queue.Push(e);
  };
  push(InputEvent::Kind::kMouseMove, p.x, p.y, false);
  push(InputEvent::Kind::kMouseButton, 0, 0, true);
  for (int s = 1; s <= 5; ++s) push(InputEvent::Kind::kMouseMove, p.x + 10 * s, p.y, false);
  push(InputEvent::Kind::kMouseButton, 0, 0, false);
  app.Drain(&queue);
  EXPECT_NEAR(Yaw(app), yaw - 0.4f * 50, 1e-3) << "the drag was lost";
}

// The New project form filled with the cube room's scene and the capture's camera, frames
// and poses, `video` instead of the frames when given.
void FillNewProject(App& app, const std::string& project_file, const std::string& video = "") {
  Activate(app, "Project", "New");  // the Project panel's New opens the form
  app.Frame();
  ASSERT_TRUE(app.Find(kNewProjectTitle).open);
  TypeInto(app, kNewProjectTitle, "##scene", SourceDir() + "/projects/cube-room/scene.gltf");
  TypeInto(app, kNewProjectTitle, "##video", video.empty() ? app.dir + "/capture/frames/" : video);
  TypeInto(app, kNewProjectTitle, "##camera", app.dir + "/capture/camera.cameramodel");
  TypeInto(app, kNewProjectTitle, "##poses", app.dir + "/capture/sparse/images.txt");
  TypeInto(app, kNewProjectTitle, "##project", project_file);
}

TEST(UiInput, NewProjectIsSavedWithRelativePathsAndOpened) {
  App app(0);
  const std::string file = app.dir + "/made/new.json";  // its folder is made too
  FillNewProject(app, file);
  Activate(app, kNewProjectTitle, "Create");
  app.Frames(2);
  EXPECT_EQ(app.ReportOf(kNewProjectTitle, "error"), "");
  ASSERT_TRUE(fs::exists(file));
  Project made;
  ASSERT_TRUE(LoadProject(file, {}, &made).ok());
  EXPECT_EQ(made.video, "../capture/frames/") << "relative to the project file";
  EXPECT_EQ(made.camera, "../capture/camera.cameramodel");
  EXPECT_EQ(made.poses, "../capture/sparse/images.txt");
  EXPECT_EQ(made.Resolve(made.scene),
            fs::path(SourceDir() + "/projects/cube-room/scene.gltf").lexically_normal().string());
  EXPECT_FALSE(app.Find(kNewProjectTitle).open) << "the form closes";
  // Opened as File > Open opens: the app edits it, and it heads the recent list.
  EXPECT_EQ(app.state.project.file_path, file);
  EXPECT_EQ(app.state.project.video, made.video);
  EXPECT_EQ(app.state.message, "opened " + file);
  ASSERT_FALSE(app.state.recent.empty());
  EXPECT_EQ(app.state.recent.front(), file);
  app.runner.WaitIdle();
  app.Frames(2);
  EXPECT_EQ(app.state.message.rfind("error: ", 0), std::string::npos) << app.state.message;
}

TEST(UiInput, NewProjectWithAMissingVideoShowsTheCommandLineErrorAndWritesNothing) {
  App app(0);
  const std::string file = app.dir + "/bad/new.json";
  FillNewProject(app, file, app.dir + "/nowhere/");
  Activate(app, kNewProjectTitle, "Create");
  app.Frames(2);
  const std::string error = app.ReportOf(kNewProjectTitle, "error");
  EXPECT_EQ(error, file + ": video: '../nowhere/' does not exist (" + app.dir + "/nowhere/)");
  EXPECT_FALSE(fs::exists(file)) << "nothing written";
  EXPECT_FALSE(fs::exists(app.dir + "/bad")) << "no folder made";
  EXPECT_TRUE(app.Find(kNewProjectTitle).open) << "the form stays, with the error";
  EXPECT_EQ(app.state.project.file_path, app.dir + "/capture/project.json");
  // The same project written by hand: `fresco run` stops on the same line.
  fs::create_directories(app.dir + "/bad");
  {
    std::ofstream out(file);
    out << "{\"fresco\": 1, \"scene\": \"" << SourceDir() << "/projects/cube-room/scene.gltf\", "
        << "\"camera\": \"../capture/camera.cameramodel\", \"video\": \"../nowhere/\", "
        << "\"poses\": \"../capture/sparse/images.txt\"}\n";
  }
  const auto run = testing::RunFresco({"run", file, "--out", app.dir + "/out"});
  EXPECT_NE(run.exit_code, 0);
  EXPECT_EQ(run.err, "error: " + error + "\n");
}

// A copy of the capture opened in the app at frame 0, and beside it broken/: the same
// capture whose frames were moved to broken/frames-moved/.
std::string BrokenCopy(App& app) {
  fs::copy(app.dir + "/capture", app.dir + "/broken", fs::copy_options::recursive);
  fs::rename(app.dir + "/broken/frames", app.dir + "/broken/frames-moved");
  return app.dir + "/broken/project.json";
}

TEST(UiInput, AProjectWithAMovedVideoIsRepairedInTheProjectPanelAndOpens) {
  App app(0);
  const std::string bad = BrokenCopy(app);
  const std::string text = testing::ReadText(bad);
  RequestOpen(app.ui, bad);
  app.Frames(2);
  EXPECT_EQ(app.state.message,
            "error: " + bad + ": video: " + app.dir + "/broken/frames/ does not exist");
  ASSERT_TRUE(app.state.has_unopened);
  EXPECT_EQ(app.state.project.file_path, app.dir + "/capture/project.json") << "still open";
  // The path editor shows the project that did not open, paths resolved.
  EXPECT_EQ(app.ReportOf("Project", "video"), app.dir + "/broken/frames/");
  EXPECT_EQ(app.ReportOf("Project", "camera"), app.dir + "/broken/camera.cameramodel");
  TypeInto(app, "Project", "##video", app.dir + "/broken/nowhere/");
  Activate(app, "Project", "Apply and save");
  EXPECT_EQ(app.ReportOf("Project", "paths error"),
            bad + ": video: 'nowhere/' does not exist (" + app.dir + "/broken/nowhere/)");
  EXPECT_EQ(testing::ReadText(bad), text) << "nothing written";
  TypeInto(app, "Project", "##video", app.dir + "/broken/frames-moved/");
  EXPECT_EQ(app.ReportOf("Project", "video"), app.dir + "/broken/frames-moved/");
  Activate(app, "Project", "Apply and save");
  app.Frames(2);
  EXPECT_EQ(app.ReportOf("Project", "paths error"), "");
  EXPECT_FALSE(app.state.has_unopened);
  EXPECT_EQ(app.state.project.file_path, bad) << "opened";
  EXPECT_EQ(app.state.project.video, "frames-moved/");
  EXPECT_EQ(app.state.message, "opened " + bad);
  Project on_disk;
  ASSERT_TRUE(LoadProject(bad, {}, &on_disk).ok());
  EXPECT_EQ(on_disk.video, "frames-moved/");
  app.runner.WaitIdle();
  app.Frames(2);
  EXPECT_EQ(app.state.message, "opened " + bad) << "the worker read it";
  ASSERT_FALSE(app.state.recent.empty());
  EXPECT_EQ(app.state.recent.front(), bad);
}

// A project that did not open beside one still open: the Project panel says which one the
// other panels show, and "Keep the open project" puts the failed one's paths aside.
TEST(UiInput, AFailedOpenSaysWhichProjectTheOtherPanelsShow) {
  App app(0);
  const std::string bad = BrokenCopy(app), good = app.dir + "/capture/project.json";
  app.ui.layout.ToggleMaximised("Project");  // room for the editor and what follows it
  RequestOpen(app.ui, bad);
  app.Frames(2);
  ASSERT_TRUE(app.state.has_unopened);
  EXPECT_EQ(app.ReportOf("Project", "paths of"), bad);
  EXPECT_EQ(app.ReportOf("Project", "video"), app.dir + "/broken/frames/");
  Activate(app, "Project", "Keep the open project");
  app.Frame();
  EXPECT_FALSE(app.state.has_unopened);
  EXPECT_EQ(app.state.project.file_path, good);
  // The path editor is the open project's again, as every other panel is.
  EXPECT_EQ(app.ReportOf("Project", "paths of"), good);
  EXPECT_EQ(app.ReportOf("Project", "video"), app.dir + "/capture/frames/");
  EXPECT_EQ(testing::ReadText(bad).find("frames-moved"), std::string::npos) << "nothing written";
}

// "Discard" in the unsaved-changes prompt lets the edits go only with a project that opens:
// when the other one does not open, the open project keeps its edits, still unsaved (the menu
// bar says so and quitting asks again).
TEST(UiInput, DiscardBeforeAFailedOpenLeavesTheEditsUnsaved) {
  App app(0);
  const std::string bad = BrokenCopy(app), good = app.dir + "/capture/project.json";
  app.state.BeginEdit();  // an unsaved settings edit
  app.state.project.pipeline.update_every = 5;
  RequestOpen(app.ui, bad);
  app.Frame();  // the prompt
  Activate(app, "Unsaved changes", "Discard");
  app.Frames(2);
  ASSERT_TRUE(app.state.has_unopened) << app.state.message;
  EXPECT_EQ(app.state.project.file_path, good);
  EXPECT_EQ(app.state.project.pipeline.update_every, 5) << "the edit is still painted";
  EXPECT_TRUE(app.state.dirty) << "the edit is not in the file";
  app.state.pending_quit = true;
  app.Frames(2);
  EXPECT_FALSE(app.ui.request_quit) << "quitting asks about the edit again";
}

TEST(UiInput, APathEditOfTheOpenProjectIsSavedRepaintedAndUndone) {
  App app(2);
  const std::string file = app.dir + "/capture/project.json";
  fs::copy(app.dir + "/capture/frames", app.dir + "/capture/frames-copy");
  app.ui.layout.ToggleMaximised("Project");  // room for the editor below the project's rows
  app.Frame();
  Activate(app, "Project", "Paths");  // opens the editor
  EXPECT_EQ(app.ReportOf("Project", "video"), app.dir + "/capture/frames/");
  TypeInto(app, "Project", "##video", app.dir + "/capture/frames-copy/");
  Activate(app, "Project", "Apply and save");
  app.Frame();
  EXPECT_EQ(app.ReportOf("Project", "paths error"), "");
  Project on_disk;
  ASSERT_TRUE(LoadProject(file, {}, &on_disk).ok());
  EXPECT_EQ(on_disk.video, "frames-copy/");
  EXPECT_EQ(app.state.project.video, "frames-copy/");
  EXPECT_FALSE(app.state.dirty) << "saved";
  app.runner.WaitIdle();
  app.Frames(2);
  EXPECT_LT(app.runner.Snapshot()->frame, 2) << "reopened: painting starts again";
  EXPECT_EQ(app.state.message.rfind("error: ", 0), std::string::npos) << app.state.message;
  // Undo: the old path is back in the app (and the editor), unsaved; the file keeps the new.
  app.input.keys_down[kKeyLeftControl] = true;
  app.Tap('Z');
  app.input.keys_down[kKeyLeftControl] = false;
  app.Frame();
  EXPECT_EQ(app.state.project.video, "frames/");
  EXPECT_TRUE(app.state.dirty);
  EXPECT_EQ(app.ReportOf("Project", "video"), app.dir + "/capture/frames/");
  ASSERT_TRUE(LoadProject(file, {}, &on_disk).ok());
  EXPECT_EQ(on_disk.video, "frames-copy/");
}

TEST(UiInput, DroppedFilesFillTheNewProjectFormOrThePathEditorOrOpenAProject) {
  App app(0);
  const std::string capture = app.dir + "/capture";
  // No form open: the open project's path editor takes a camera.
  DropPaths(app.ui, {capture + "/sparse/cameras.txt"});
  app.Frame();
  EXPECT_EQ(app.ReportOf("Project", "camera"), capture + "/sparse/cameras.txt");
  EXPECT_EQ(app.state.message, "dropped camera " + capture +
                                   "/sparse/cameras.txt into Project (Apply and save keeps it)");
  EXPECT_EQ(app.state.project.camera, "camera.cameramodel") << "not applied yet";
  // The form open: it takes every field, the path editor nothing more.
  Activate(app, "Project", "New");
  app.Frame();
  ASSERT_TRUE(app.Find(kNewProjectTitle).open);
  const std::string scene = SourceDir() + "/projects/cube-room/scene.gltf";
  DropPaths(app.ui, {scene, capture + "/frames", capture + "/camera.cameramodel",
                     capture + "/sparse/images.txt"});
  app.Frame();
  EXPECT_EQ(app.ReportOf(kNewProjectTitle, "scene"), scene);
  EXPECT_EQ(app.ReportOf(kNewProjectTitle, "video"), capture + "/frames/");
  EXPECT_EQ(app.ReportOf(kNewProjectTitle, "camera"), capture + "/camera.cameramodel");
  EXPECT_EQ(app.ReportOf(kNewProjectTitle, "poses"), capture + "/sparse/images.txt");
  EXPECT_EQ(app.ReportOf("Project", "video"), capture + "/frames/") << "the editor unchanged";
  // What it is not: one message naming the file, nothing else changes.
  testing::WriteText(app.dir + "/notes.md", "notes\n");
  DropPaths(app.ui, {app.dir + "/notes.md"});
  app.Frame();
  EXPECT_EQ(app.state.message.rfind("error: " + app.dir + "/notes.md: dropped, but it is not", 0),
            0u)
      << app.state.message;
  EXPECT_EQ(app.ReportOf(kNewProjectTitle, "scene"), scene);
  // A project opens.
  fs::copy(capture + "/project.json", capture + "/second.json");
  DropPaths(app.ui, {capture + "/second.json"});
  app.Frames(2);
  EXPECT_EQ(app.state.project.file_path, capture + "/second.json");
  EXPECT_EQ(app.state.message, "opened " + capture + "/second.json");
}

}  // namespace
}  // namespace fresco

namespace fresco {
namespace {

// The File menu's Open... and Save As...: a path typed into the submenu, then its item.
// Returns the submenu's window after hovering `entry` (the File menu open).
ImGuiWindow* OpenFileSubmenu(App& app, int entry) {
  const float line = ImGui::GetFrameHeight();
  app.Click(ImVec2(15, line / 2));  // "File" in the menu bar
  ImGuiWindow* file = ImGui::FindWindowByName("##Menu_00");
  EXPECT_NE(file, nullptr);
  if (!file) return nullptr;
  const float item = ImGui::GetTextLineHeight() + ImGui::GetStyle().ItemSpacing.y;
  const ImVec2 at(file->Pos.x + 30, file->DC.CursorStartPos.y + (entry + 0.5f) * item);
  app.MouseTo(at.x, at.y);
  app.Frames(3);
  ImGuiWindow* sub = ImGui::FindWindowByName("##Menu_01");
  EXPECT_NE(sub, nullptr);
  return sub;
}

TEST(UiInput, TheFileMenuSavesAsAndOpensATypedPath) {
  App app(0);
  const std::string copy = app.dir + "/capture/saved-from-menu.json";
  ImGuiWindow* save_as = OpenFileSubmenu(app, 3);  // New project, Open, Save, Save As
  ASSERT_NE(save_as, nullptr);
  testing::TypeInto(app, save_as->Name, "##menu_save_as", copy);
  EXPECT_EQ(app.ui.menu_path, copy);
  ImGui::ActivateItem(save_as->GetID("Save As"));
  app.Frames(2);
  ASSERT_TRUE(fs::is_regular_file(copy)) << app.state.message;
  EXPECT_EQ(app.state.project.file_path, copy);
  // Back to the first through Open... (the field cleared, as a user selects and retypes).
  const std::string first = app.dir + "/capture/project.json";
  app.ui.menu_path.clear();
  ImGuiWindow* open = OpenFileSubmenu(app, 1);
  ASSERT_NE(open, nullptr);
  testing::TypeInto(app, open->Name, "##menu_open", first);
  ImGui::ActivateItem(open->GetID("Open"));
  app.Frames(2);
  app.runner.WaitIdle();
  app.Frames(2);
  EXPECT_EQ(app.state.project.file_path, first) << app.state.message;
  EXPECT_EQ(app.state.message.rfind("opened ", 0), 0u) << app.state.message;
}

// Paths (issue 58, item 4): an empty field's "..." starts in the last folder used (not the
// launch folder), in every form: New project, the Calibration folder (which has a browser
// now) and File > Open, whose field is wide enough to read a path; a folder of frames says
// what it holds instead of "nothing here fits".
TEST(UiInput, EveryPathListStartsInTheLastFolderUsed) {
  App app(0);
  const std::string browse = fs::absolute(app.dir + "/browse").lexically_normal().string() + "/";
  fs::create_directories(browse + "frames");
  std::ofstream(browse + "mesh.ply") << "ply\n";
  for (const char* name : {"000000.png", "000001.png", "000002.png"})
    std::ofstream(browse + "frames/" + name) << "png";
  const auto list = [] {
    for (ImGuiWindow* w : GImGui->Windows)
      if ((w->Flags & ImGuiWindowFlags_Popup) && w->Active) return w;
    return static_cast<ImGuiWindow*>(nullptr);
  };
  const auto browse_of = [&](const std::string& window, const char* id) {
    ImGui::ActivateItem(ImHashStr("...", 0, App::Window(window)->GetID(id)));
    app.Frames(2);
  };
  const auto pick = [&](const char* label) {
    ImGuiWindow* popup = list();
    ASSERT_NE(popup, nullptr) << "the list is not open to pick " << label;
    ImGui::ActivateItem(popup->GetID(label));
    app.Frames(2);
  };
  Activate(app, "Project", "New");
  app.Frame();
  TypeInto(app, kNewProjectTitle, "##scene", browse);
  browse_of(kNewProjectTitle, "##scene");
  pick("mesh.ply");
  EXPECT_EQ(app.state.last_folder, browse);
  // The video field is empty: its list opens in that folder, and a frame folder is a choice.
  browse_of(kNewProjectTitle, "##video");
  EXPECT_EQ(app.ReportOf(kNewProjectTitle, "video"), browse);
  ASSERT_NE(list(), nullptr);
  pick("frames/");
  EXPECT_EQ(app.ReportOf(kNewProjectTitle, "video"), browse + "frames/");
  PathFieldOptions video;
  video.folder_of_images = true;
  EXPECT_EQ(BrowseNote(browse + "frames/", video, 0), "this folder: 3 images (chosen)");
  EXPECT_EQ(BrowseNote(browse + "frames/", {}, 0), "nothing here fits");
  EXPECT_EQ(app.state.last_folder, browse + "frames/");
  ImGui::ClosePopupsOverWindow(nullptr, false);
  app.Frames(2);

  // The Calibration panel's folder has a browser, starting there too.
  app.Find(kCalibrationPanelTitle).open = true;
  app.Frames(2);
  browse_of(kCalibrationPanelTitle, "##folder");
  EXPECT_EQ(app.ReportOf(kCalibrationPanelTitle, "folder"), browse + "frames/");
  ImGui::ClosePopupsOverWindow(nullptr, false);
  app.Frames(2);

  // File > Open...: the field is a path's width, and its list starts there.
  app.ui.menu_path.clear();
  ImGuiWindow* open = OpenFileSubmenu(app, 1);
  ASSERT_NE(open, nullptr);
  EXPECT_GE(open->Size.x, 30 * ImGui::GetFontSize()) << "File > Open's field is too narrow";
  ImGui::ActivateItem(ImHashStr("...", 0, open->GetID("##menu_open")));
  app.Frames(2);
  EXPECT_EQ(app.ui.menu_path, browse + "frames/");
}

// The "..." beside a path field browses: a folder opens in place (the list stays open), the
// entry above goes up, only the fitting files are listed, and picking a file fills the field
// and closes the list.
TEST(UiInput, ThePathFieldBrowsesFoldersUpAndDownAndPicksAFile) {
  App app(0);
  const std::string browse = app.dir + "/browse/";
  fs::create_directories(browse + "sub");
  std::ofstream(browse + "mesh.ply") << "ply\n";
  std::ofstream(browse + "other.ply") << "ply\n";
  std::ofstream(browse + "notes.md") << "not a mesh\n";
  std::ofstream(browse + "sub/inner.obj") << "v 0 0 0\n";
  Activate(app, "Project", "New");
  app.Frame();
  ASSERT_TRUE(app.Find(kNewProjectTitle).open);
  TypeInto(app, kNewProjectTitle, "##scene", browse);
  ImGuiWindow* form = App::Window(kNewProjectTitle);
  ImGui::ActivateItem(ImHashStr("...", 0, form->GetID("##scene")));
  app.Frames(2);
  const auto list = [] {
    for (ImGuiWindow* w : GImGui->Windows)
      if ((w->Flags & ImGuiWindowFlags_Popup) && w->Active) return w;
    return static_cast<ImGuiWindow*>(nullptr);
  };
  const auto pick = [&](const char* label) {
    ImGuiWindow* popup = list();
    ASSERT_NE(popup, nullptr) << "the list is not open to pick " << label;
    ImGui::ActivateItem(popup->GetID(label));
    app.Frames(2);
  };
  const auto scene = [&] { return app.ReportOf(kNewProjectTitle, "scene"); };
  pick("sub/");
  EXPECT_EQ(scene(), browse + "sub/");
  ASSERT_NE(list(), nullptr) << "a folder opens in place";
  pick("../ (the folder above)");
  EXPECT_EQ(scene(), browse);
  EXPECT_EQ(ParentFolder(browse + "mesh"), app.dir + "/");
  EXPECT_EQ(BrowseEntries(browse, {".ply"}),
            (std::vector<std::string>{browse + "mesh.ply", browse + "other.ply", browse + "sub/"}));
  EXPECT_EQ(BrowseEntries(browse + "m", {".ply"}), (std::vector<std::string>{browse + "mesh.ply"}));
  pick("mesh.ply");
  EXPECT_EQ(scene(), browse + "mesh.ply");
  EXPECT_EQ(list(), nullptr) << "a file picked closes the list";
  // Browsing again from the file picked lists its whole folder, to pick another.
  ImGui::ActivateItem(ImHashStr("...", 0, form->GetID("##scene")));
  app.Frames(2);
  pick("other.ply");
  EXPECT_EQ(scene(), browse + "other.ply") << "the list held only the file picked before";
  EXPECT_EQ(ParentFolder("/"), "");
  EXPECT_EQ(ParentFolder("/usr/"), "/");
  EXPECT_EQ(ParentFolder("mesh.ply"), "../");
  EXPECT_EQ(ParentFolder("../x"), "../../");
  EXPECT_EQ(ParentFolder("a/b/x"), "a/");
  EXPECT_EQ(ParentFolder("a/x"), "./");
}

}  // namespace
}  // namespace fresco
