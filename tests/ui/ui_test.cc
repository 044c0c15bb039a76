// The app without a display: every panel drawn by Dear ImGui with null image and viewport
// backends (no GL), over a real painting worker on a small synthetic capture; the app's
// project edits (undo/redo, save, grouping edits) and that `fresco run` honours them; and,
// when xvfb-run is there, a real screenshot of the GL app.
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <set>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <imgui.h>
#include <imgui_internal.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "calib/report.h"
#include "pipeline/core/poses.h"
#include "pipeline/core/run_process.h"
#include "pipeline/core/scene.h"
#include "tests/poses/perturbed_pose.h"
#include "tests/test_support.h"
#include "tests/ui/headless_ui.h"
#include "ui/core/app_frame.h"
#include "ui/core/calibration_runner.h"
#include "ui/core/orbit_frame.h"
#include "ui/core/panel.h"
#include "ui/core/poses_runner.h"
#include "ui/panels/panels.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using testing::ImGuiHeadless;
using testing::MakeTempDir;
using testing::NullTextures;
using testing::NullViewport;
using testing::ReadText;
using testing::RunFresco;

using testing::Capture;

TEST(UiHeadless, EveryPanelDrawsTheWorkersSnapshot) {
  AppState state;
  ASSERT_TRUE(state.Open(Capture() + "/project.json").ok());
  PipelineRunner runner;
  runner.Restart(state.project);
  runner.Seek(5);
  runner.WaitIdle();
  NullTextures textures;
  NullViewport viewport;
  CalibrationRunner calibration;  // no folder: the Calibration panel shows its inputs
  UiContext ui{&state, &runner, &calibration, &textures, &viewport, nullptr, false};
  ImGuiHeadless imgui;
  auto panels = MakePanels();
  ASSERT_GE(panels.size(), 11u);
  for (auto& panel : panels) panel->open = true;
  for (int i = 0; i < 3; ++i) {
    ui.snapshot = runner.Snapshot();
    imgui.Frame(ui, panels);
  }
  const RunnerSnapshot& snap = *ui.snapshot;
  EXPECT_EQ(snap.frame, 5);
  EXPECT_EQ(snap.status, "paused");
  ASSERT_TRUE(snap.geometry);
  EXPECT_EQ(snap.geometry->groups.size(), 6u);
  ASSERT_TRUE(snap.painted);
  EXPECT_EQ(snap.painted->size(), 6u);
  EXPECT_EQ(snap.stage_ms.at("warp").size(), 6u);  // frames 0..5
  EXPECT_EQ(snap.misalignment.size(), 6u);
  EXPECT_GT(snap.coverage, 0.05);
  // The shown frame has its debug images and the misalignment review.
  EXPECT_FALSE(snap.report.Stage("warp")->images.empty());
  EXPECT_FALSE(snap.rephoto_bgr.empty());
  EXPECT_FALSE(snap.difference_heat.empty());
  // Every panel is a visible window (brought to the front of its tab group first: the tools
  // share the stage row's place), and images went through the texture backend.
  for (const auto& panel : panels) {
    if (ui.layout.ShowTab(panel->Title())) imgui.Frame(ui, panels);
    ImGuiWindow* window = ImGui::FindWindowByName(PanelWindowId(panel->Title()).c_str());
    ASSERT_NE(window, nullptr) << panel->Title();
    EXPECT_TRUE(window->Active || window->WasActive) << panel->Title();
    EXPECT_GT(window->Size.x, 100) << panel->Title();
  }
  EXPECT_TRUE(textures.keys.count("input"));
  EXPECT_GT(viewport.renders, 0);
  // Stepping paints one more frame.
  runner.Step();
  runner.WaitIdle();
  EXPECT_EQ(runner.Snapshot()->frame, 6);
  // Seeking back restarts and repaints up to the frame.
  runner.Seek(2);
  runner.WaitIdle();
  EXPECT_EQ(runner.Snapshot()->frame, 2);
  EXPECT_EQ(runner.Snapshot()->stage_ms.at("warp").size(), 3u);
}

// A project with two streams (a fixed wide-lens camera and a hand-held one): the app paints
// both, as `fresco run` does (the same coverage), counts its frames over both, keeps each
// stream's camera and path for the 3D view and each stream's latest frame for the Input
// frame panel.
TEST(UiHeadless, ATwoStreamProjectPaintsBothStreamsAsTheRunDoes) {
  const std::string dir = testing::MakeTempDir("ui-streams");
  testing::WriteText(dir + "/spec.json", R"({
    "scene": "builtin:cube-room", "size": [160, 120], "frames": 12, "seed": 3,
    "streams": [
      {"name": "fixed", "path": {"kind": "fixed"}, "lens": "opencv5", "hfov_deg": 80,
       "frames": 4},
      {"name": "hand", "path": {"kind": "handheld", "turns": 0.5, "start_deg": 200},
       "lens": "pinhole", "size": [200, 150]}]})");
  const auto synth = RunFresco({"synth", dir + "/spec.json", "--out", dir + "/capture"});
  ASSERT_EQ(synth.exit_code, 0) << synth.err;
  const std::string project = dir + "/capture/project.json";
  const auto run = RunFresco({"run", project, "--out", dir + "/out", "--quiet"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const double run_coverage =
      nlohmann::json::parse(ReadText(dir + "/out/metrics.json"))["coverage"].get<double>();

  AppState state;
  const Status opened = state.Open(project);
  ASSERT_TRUE(opened.ok()) << opened.message();
  PipelineRunner runner;
  runner.Restart(state.project);
  runner.WaitIdle();
  std::shared_ptr<const RunnerSnapshot> snap = runner.Snapshot();
  ASSERT_TRUE(snap->geometry);
  ASSERT_EQ(snap->geometry->stream_cameras.size(), 2u);
  EXPECT_EQ(snap->geometry->stream_cameras[0].width, 160);
  EXPECT_EQ(snap->geometry->stream_cameras[1].width, 200);
  EXPECT_EQ(snap->geometry->stream_paths[0].size(), 4u);
  EXPECT_EQ(snap->geometry->stream_paths[1].size(), 12u);
  EXPECT_EQ(snap->geometry->num_frames, 16);
  runner.Seek(15);  // the last frame of the two streams (counted over both)
  runner.WaitIdle();
  snap = runner.Snapshot();
  EXPECT_EQ(snap->frame, 15);
  EXPECT_EQ(snap->run.frames_painted, 16);
  ASSERT_EQ(snap->run.streams.size(), 2u);
  EXPECT_EQ(snap->run.streams[0].painted, 4);
  EXPECT_EQ(snap->run.streams[1].painted, 12);
  ASSERT_EQ(snap->stream_frames.size(), 2u);
  const int width = snap->stream == 0 ? 160 : 200;  // the shown frame is its stream's latest
  EXPECT_EQ(snap->frame_bgr.cols, width);
  EXPECT_EQ(snap->stream_frames[snap->stream].cols, width);
  EXPECT_EQ(snap->frame_name.rfind("stream " + std::to_string(snap->stream) + " ", 0), 0u)
      << snap->frame_name;
  EXPECT_DOUBLE_EQ(snap->coverage, run_coverage) << "the app paints what fresco run paints";
  // Back to the first frame read: the fixed camera's (both streams start at time 0; the
  // first stream first).
  runner.Seek(0);
  runner.WaitIdle();
  snap = runner.Snapshot();
  EXPECT_EQ(snap->stream, 0);
  EXPECT_EQ(snap->frame_bgr.cols, 160);
  // The panels draw it (the Input frame panel offers each stream's latest frame).
  NullTextures textures;
  NullViewport viewport;
  UiContext ui{&state, &runner, nullptr, &textures, &viewport, snap, false};
  ImGuiHeadless imgui;
  auto panels = MakePanels();
  for (auto& panel : panels) panel->open = true;
  for (int i = 0; i < 2; ++i) imgui.Frame(ui, panels);
  for (const auto& panel : panels) {
    if (std::string(panel->Title()) == "Input frame") {
      EXPECT_EQ(panel->Report().at("stream"), "latest");
    }
  }
}

// Endless live streams (the app runs for hours): the per-frame histories keep only the latest
// frames.
TEST(UiHeadless, PerFrameHistoriesAreBounded) {
  AppState state;
  ASSERT_TRUE(state.Open(Capture() + "/project.json").ok());
  RunnerOptions options;
  options.history_frames = 2;
  options.misalignment = false;
  PipelineRunner runner(options);
  runner.Restart(state.project);
  runner.Seek(11);
  runner.WaitIdle();
  const auto snap = runner.Snapshot();
  EXPECT_EQ(snap->frame, 11);
  ASSERT_GE(snap->frames_painted.size(), 2u);
  EXPECT_LT(snap->frames_painted.size(), 4u);
  EXPECT_EQ(snap->frames_painted.back(), 11);
  EXPECT_EQ(snap->frames_painted[snap->frames_painted.size() - 2], 10);
  EXPECT_EQ(snap->misalignment.size(), snap->frames_painted.size());
  EXPECT_LT(snap->stage_ms.at("warp").size(), 4u);
}

TEST(UiHeadless, BadProjectIsReportedNotFatal) {
  AppState state;
  const Status s = state.Open("/no/such/project.json");
  EXPECT_FALSE(s.ok());
  EXPECT_FALSE(state.has_project);
  PipelineRunner runner;
  Project broken;  // points at nothing
  broken.scene = "missing.gltf";
  broken.camera = "missing.cameramodel";
  broken.video = "frames/";
  broken.poses = "images.txt";
  broken.file_path = MakeTempDir("ui-bad") + "/project.json";
  runner.Restart(broken);
  runner.WaitIdle();
  EXPECT_EQ(runner.Snapshot()->status.rfind("error: ", 0), 0u) << runner.Snapshot()->status;
  runner.Step();  // nothing to paint: no crash
  runner.WaitIdle();
}

TEST(UiState, UndoRedoDirtyAndAtomicSave) {
  const std::string dir = MakeTempDir("ui-state");
  fs::copy(Capture(), dir + "/capture", fs::copy_options::recursive);
  AppState state;
  ASSERT_TRUE(state.Open(dir + "/capture/project.json").ok());
  EXPECT_FALSE(state.dirty);
  state.BeginEdit();
  state.project.pipeline.update_every = 7;
  EXPECT_TRUE(state.dirty);
  state.BeginEdit();
  state.project.pipeline.sampling = SamplingMode::kArea;
  ASSERT_TRUE(state.Undo());
  EXPECT_EQ(state.project.pipeline.sampling, SamplingMode::kBilinear);
  EXPECT_EQ(state.project.pipeline.update_every, 7);
  ASSERT_TRUE(state.Redo());
  EXPECT_EQ(state.project.pipeline.sampling, SamplingMode::kArea);
  ASSERT_TRUE(state.Save().ok());
  EXPECT_FALSE(state.dirty);
  Project reloaded;
  ASSERT_TRUE(LoadProject(dir + "/capture/project.json", {}, &reloaded).ok());
  EXPECT_EQ(reloaded.pipeline, state.project.pipeline);
  // Save As elsewhere keeps paths pointing at the same files.
  ASSERT_TRUE(state.Save(dir + "/copy.json").ok());
  Project copy;
  ASSERT_TRUE(LoadProject(dir + "/copy.json", {}, &copy).ok());
  EXPECT_EQ(fs::canonical(copy.Resolve(copy.scene)),
            fs::canonical(reloaded.Resolve(reloaded.scene)));
  // A save that cannot be written leaves the old file and reports the path.
  const Status bad = state.Save(dir + "/no/such/folder/p.json");
  EXPECT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("no/such/folder"), std::string::npos) << bad.message();
}

// The analyst's grouping edit, scripted the way the grouping panel does it: split one
// triangle into a group of its own and give it a coarser texel size; saved, reloaded, and
// painted by `fresco run` with exactly those groups.
TEST(UiState, GroupingEditIsSavedReloadedAndHonouredByRun) {
  const std::string dir = MakeTempDir("ui-group");
  fs::copy(Capture(), dir + "/capture", fs::copy_options::recursive);
  const std::string path = dir + "/capture/project.json";
  AppState state;
  ASSERT_TRUE(state.Open(path).ok());
  PipelineRunner runner;
  runner.Restart(state.project);
  runner.WaitIdle();
  const auto geometry = runner.Snapshot()->geometry;
  ASSERT_TRUE(geometry);
  const int num_triangles = static_cast<int>(geometry->buffer_of_triangle.size());
  std::vector<GroupSpec> split, coarse;
  ASSERT_TRUE(SplitTriangles(geometry->groups, num_triangles, {0}, &split).ok());
  ASSERT_EQ(split.size(), 7u);
  ASSERT_TRUE(SetGroupTexelSize(split, num_triangles, {6}, 0.05, &coarse).ok());
  state.BeginEdit();
  state.project.grouping.groups = coarse;
  ASSERT_TRUE(state.Save().ok());
  // Bad edits name what is wrong.
  std::vector<GroupSpec> unused;
  const Status bad = MergeGroups(geometry->groups, num_triangles, {0, 42}, &unused);
  EXPECT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("group 42"), std::string::npos) << bad.message();

  Project reloaded;
  ASSERT_TRUE(LoadProject(path, {}, &reloaded).ok());
  EXPECT_EQ(reloaded.grouping.groups, coarse);
  const std::string out = dir + "/out";
  const auto r = RunFresco({"run", path, "--out", out, "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json m = nlohmann::json::parse(ReadText(out + "/metrics.json"));
  EXPECT_EQ(m["base_buffers"], 7);
  int coarse_buffers = 0;
  for (const auto& b : m["buffers"])
    coarse_buffers +=
        b["triangles"] == 1 && std::abs(b["texel_size_m"].get<double>() - 0.05) < 1e-9;
  EXPECT_EQ(coarse_buffers, 1);
  // The app, reopened on the saved project, builds the same groups.
  runner.Restart(reloaded);
  runner.WaitIdle();
  EXPECT_EQ(runner.Snapshot()->geometry->groups.size(), 7u);
}

// The real app under Xvfb (Mesa): `fresco gui --screenshot` paints, draws every panel and
// writes the window; the picture is not empty and every panel is where the list says.
TEST(UiScreenshot, XvfbScreenshotShowsEveryPanel) {
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed (apt-get install xvfb xauth): skipped";
  const std::string dir = MakeTempDir("ui-shot");
  const std::string shot = dir + "/app.png";
  const auto r = RunFresco(
      {"--xvfb", "gui", Capture() + "/project.json", "--screenshot", shot, "--frames", "8"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const cv::Mat image = cv::imread(shot);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 1600);
  EXPECT_EQ(image.rows, 1000);
  cv::Scalar mean, stddev;
  cv::meanStdDev(image, mean, stddev);
  EXPECT_GT(stddev[0] + stddev[1] + stddev[2], 30.0);  // not a blank window
  const nlohmann::json list = nlohmann::json::parse(ReadText(shot + ".json"));
  ASSERT_GE(list["panels"].size(), 11u);
  for (const auto& panel : list["panels"]) {
    const std::string title = panel["title"];
    if (title == kCalibrationPanelTitle || title == kPosesPanelTitle ||
        title == kNewProjectTitle) {  // closed at first
      EXPECT_FALSE(panel["open"].get<bool>());
      continue;
    }
    ASSERT_TRUE(panel["open"].get<bool>()) << title;
    ASSERT_TRUE(panel.contains("width")) << title;
    EXPECT_FALSE(panel["collapsed"].get<bool>()) << title;
    const cv::Rect rect(static_cast<int>(panel["x"].get<double>()),
                        static_cast<int>(panel["y"].get<double>()),
                        static_cast<int>(panel["width"].get<double>()),
                        static_cast<int>(panel["height"].get<double>()));
    const cv::Rect inside = rect & cv::Rect(0, 0, image.cols, image.rows);
    ASSERT_GT(inside.area(), 100 * 100) << title;
    cv::meanStdDev(image(inside), mean, stddev);
    EXPECT_GT(stddev[0] + stddev[1] + stddev[2], 10.0) << title << ": an empty panel";
  }
}

// The left images of opencv-chessboard-stereo (the folder also holds the right ones).
std::string ChessboardLeftImages() {
  static const std::string dir = [] {
    const std::string data = fresco::testing::SharedDataDir() + "/opencv-chessboard-stereo";
    const std::string d = MakeTempDir("ui-calib") + "/left";
    fs::create_directories(d);
    for (const auto& e : fs::directory_iterator(data))
      if (e.path().filename().string().rfind("left", 0) == 0 && e.path().extension() == ".jpg")
        fs::copy(e.path(), d + "/" + e.path().filename().string());
    return d;
  }();
  return dir;
}

// Detects the 9x6 chessboard of opencv-chessboard-stereo in `dir` (model opencv4) and waits.
std::shared_ptr<const CalibrationSnapshot> DetectChessboard(const std::string& dir,
                                                            CalibrationRunner* runner) {
  calib::CalibrateRequest request;
  request.images_dir = dir;
  EXPECT_TRUE(calib::ParseBoardSpec("chessboard:9x6:0.025", "board", &request.board).ok());
  request.model = "opencv4";
  runner->Detect(request);
  runner->WaitIdle();
  return runner->Snapshot();
}

// The calibration worker: detections arrive image by image, the light turns from red once
// kMinViews boards are seen, the solve picks the requested model, Save writes what the CLI does.
TEST(CalibrationRunner, DetectsSolvesAndSavesTheChessboard) {
  FRESCO_REQUIRE_SHARED_DATA();
  CalibrationRunner runner;
  auto snap = DetectChessboard(ChessboardLeftImages(), &runner);
  EXPECT_EQ(snap->images.size(), 13u);
  EXPECT_EQ(snap->images_done, 13);
  EXPECT_EQ(snap->run.views.size(), 13u);
  EXPECT_FALSE(snap->solved);
  EXPECT_NE(snap->readiness.level, calib::DataReadiness::Level::kRed);
  EXPECT_GT(snap->readiness.max_tilt_deg, 0);  // seeded from the detections
  EXPECT_FALSE(snap->coverage_picture.empty());
  runner.Solve();
  runner.WaitIdle();
  snap = runner.Snapshot();
  ASSERT_TRUE(snap->solved) << snap->status;
  EXPECT_EQ(snap->run.Chosen().short_name, "opencv4");
  EXPECT_LT(std::abs(snap->run.Chosen().fit.intrinsics[0] - 535.92) / 535.92, 0.005);
  EXPECT_FALSE(snap->residuals_picture.empty());
  const std::string out = MakeTempDir("ui-calib-save") + "/cam/left.cameramodel";
  runner.Save(out);
  runner.WaitIdle();
  EXPECT_EQ(runner.Snapshot()->saved_path, out) << runner.Snapshot()->status;
  EXPECT_TRUE(fs::exists(out));
  EXPECT_TRUE(fs::exists(calib::SiblingPath(out, ".report.json")));
  EXPECT_TRUE(fs::exists(calib::SiblingPath(out, ".coverage.png")));
  {  // New project offers the camera just saved.
    UiContext ui;
    ui.calibration = &runner;
    ImGuiHeadless imgui;
    std::unique_ptr<Panel> form;
    for (auto& p : MakePanels())
      if (std::string(p->Title()) == kNewProjectTitle) form = std::move(p);
    ASSERT_TRUE(form);
    ImGuiHeadless::DrawPanel(ui, *form, ImVec2(760, 300));
    const std::string button = "Use the camera just calibrated: " + out;
    ImGui::ActivateItem(
        ImGui::FindWindowByName(PanelWindowId(kNewProjectTitle).c_str())->GetID(button.c_str()));
    ImGuiHeadless::DrawPanel(ui, *form, ImVec2(760, 300));
    EXPECT_EQ(form->Report().at("camera"), out);
  }

  // The per-image checkbox: an excluded image leaves the views and the solve goes stale.
  runner.Exclude("left03.jpg", true);
  runner.WaitIdle();
  snap = runner.Snapshot();
  EXPECT_EQ(snap->run.views.size(), 12u);
  ASSERT_EQ(snap->run.excluded.size(), 1u);
  EXPECT_EQ(snap->run.excluded[0], "left03.jpg");
  EXPECT_FALSE(snap->solved);
  runner.Solve();
  runner.WaitIdle();
  snap = runner.Snapshot();
  ASSERT_TRUE(snap->solved) << snap->status;
  EXPECT_EQ(snap->run.Chosen().fit.views.size(), 12u);
  runner.Exclude("left03.jpg", false);
  runner.WaitIdle();
  EXPECT_EQ(runner.Snapshot()->run.views.size(), 13u);
  EXPECT_TRUE(runner.Snapshot()->run.excluded.empty());
}

// Cancel stops a solve before its next fit: nothing solved, the detections kept, the status
// says so; a solve afterwards runs to its end.
TEST(CalibrationRunner, ASolveCanBeCancelled) {
  FRESCO_REQUIRE_SHARED_DATA();
  CalibrationRunner runner;
  auto snap = DetectChessboard(ChessboardLeftImages(), &runner);
  ASSERT_EQ(snap->run.views.size(), 13u);
  runner.Solve();
  runner.Cancel();
  runner.WaitIdle();
  snap = runner.Snapshot();
  EXPECT_FALSE(snap->solved);
  EXPECT_FALSE(snap->solving);
  EXPECT_EQ(snap->status.rfind("cancelled: the solve stopped after ", 0), 0u) << snap->status;
  EXPECT_EQ(snap->run.views.size(), 13u);
  runner.Solve();
  runner.WaitIdle();
  snap = runner.Snapshot();
  EXPECT_TRUE(snap->solved) << snap->status;
  EXPECT_GT(snap->solves_total, 0);
}

// A folder with both cameras of opencv-chessboard-stereo (left and right images, one size):
// after Detect, before any solve, the light is off green and the panel's reason says two
// cameras; once the right images are ticked off (13 in a row, checked once after the last),
// the doubt is gone.
TEST(CalibrationRunner, AFolderOfTwoCamerasIsToldRightAfterDetection) {
  FRESCO_REQUIRE_SHARED_DATA();
  const std::string data = fresco::testing::SharedDataDir() + "/opencv-chessboard-stereo";
  const std::string dir = MakeTempDir("ui-calib-mixed") + "/both";
  fs::create_directories(dir);
  for (const auto& e : fs::directory_iterator(data))
    if (e.path().extension() == ".jpg")
      fs::copy(e.path(), dir + "/" + e.path().filename().string());
  CalibrationRunner runner;
  auto snap = DetectChessboard(dir, &runner);
  EXPECT_EQ(snap->run.views.size(), 26u);
  EXPECT_FALSE(snap->solved);
  ASSERT_FALSE(snap->run.camera_doubts.empty());
  EXPECT_NE(snap->run.camera_doubts[0].find("look like two cameras"), std::string::npos);
  EXPECT_NE(snap->readiness.level, calib::DataReadiness::Level::kGreen);
  EXPECT_NE(std::find(snap->readiness.reasons.begin(), snap->readiness.reasons.end(),
                      snap->run.camera_doubts[0]),
            snap->readiness.reasons.end());
  for (const CalibrationImage& image : snap->images)
    if (image.name.rfind("right", 0) == 0) runner.Exclude(image.name, true);
  runner.WaitIdle();
  snap = runner.Snapshot();
  EXPECT_EQ(snap->run.views.size(), 13u);
  EXPECT_TRUE(snap->run.camera_doubts.empty()) << snap->run.camera_doubts[0];
}

// Every third image of aprilgrid-yac-mocap's cam0 (10 of 30): a real Kalibr AprilGrid.
std::string AprilGridImages() {
  static const std::string dir = [] {
    const std::string data = fresco::testing::SharedDataDir() + "/aprilgrid-yac-mocap/cam0/data";
    const std::string d = MakeTempDir("ui-calib-april") + "/cam0";
    fs::create_directories(d);
    std::vector<fs::path> images;
    for (const auto& e : fs::directory_iterator(data))
      if (e.path().extension() == ".jpg") images.push_back(e.path());
    std::sort(images.begin(), images.end());
    for (size_t i = 0; i < images.size(); i += 3)
      fs::copy(images[i], d + "/" + images[i].filename().string());
    return d;
  }();
  return dir;
}

// The same worker and the Calibration panel with an AprilGrid: partial boards detected tag by
// tag, the solve, and the panel (drawn headless) showing the detections, coverage, residuals
// and projection-uncertainty pictures and the chosen model.
TEST(CalibrationRunner, AprilGridDetectsSolvesAndThePanelShowsIt) {
  FRESCO_REQUIRE_SHARED_DATA();
  calib::CalibrateRequest request;
  request.images_dir = AprilGridImages();
  ASSERT_TRUE(calib::ParseBoardSpec("aprilgrid:6x6:0.088:0.3", "board", &request.board).ok());
  request.model = "opencv4";
  request.cross_validate = false;
  CalibrationRunner runner;
  runner.Detect(request);
  runner.WaitIdle();
  auto snap = runner.Snapshot();
  ASSERT_EQ(snap->images.size(), 10u);
  EXPECT_EQ(snap->run.views.size(), 10u) << snap->status;
  for (const calib::BoardView& v : snap->run.views) {
    EXPECT_GE(v.corners.size(), 40u) << v.name;  // tags of a 6x6 grid, some boards partial
    EXPECT_LE(v.corners.size(), 144u) << v.name;
  }
  EXPECT_NE(snap->readiness.level, calib::DataReadiness::Level::kRed);
  runner.Solve();
  runner.WaitIdle();
  snap = runner.Snapshot();
  ASSERT_TRUE(snap->solved) << snap->status;
  const calib::SolveResult& fit = snap->run.Chosen().fit;
  EXPECT_EQ(fit.lensmodel, "LENSMODEL_OPENCV4");
  EXPECT_NEAR(fit.intrinsics[0], 610.1, 0.02 * 610.1);  // all 30 images, CLI: 610.13
  EXPECT_NEAR(fit.intrinsics[2], 325.9, 6.0);
  EXPECT_LT(fit.rms_px, 0.4);
  EXPECT_GT(snap->run.uncertainty.centre_px, 0);
  EXPECT_FALSE(snap->uncertainty_picture.empty());

  NullTextures textures;
  UiContext ui{nullptr, nullptr, &runner, &textures, nullptr, nullptr, false};
  ImGuiHeadless imgui;
  std::unique_ptr<Panel> panel;
  for (auto& p : MakePanels())
    if (std::string(p->Title()) == kCalibrationPanelTitle) panel = std::move(p);
  ASSERT_TRUE(panel);
  for (int i = 0; i < 3; ++i) ImGuiHeadless::DrawPanel(ui, *panel, ImVec2(900, 2400));
  for (const char* key : {"calibration image", "calibration coverage", "calibration residuals",
                          "calibration uncertainty"})
    EXPECT_TRUE(textures.keys.count(key)) << key;
  const auto report = panel->Report();
  EXPECT_EQ(report.at("model"), "opencv4");
  EXPECT_EQ(report.at("views"), "10");
  EXPECT_NEAR(std::stod(report.at("fx")), fit.intrinsics[0], 1e-3);
  EXPECT_GT(std::stod(report.at("uncertainty_max_px")),
            std::stod(report.at("uncertainty_centre_px")));
}

TEST(CalibrationRunner, MissingFolderIsAnError) {
  calib::CalibrateRequest request;
  request.images_dir = "/no/such/folder";
  ASSERT_TRUE(calib::ParseBoardSpec("chessboard:9x6:0.025", "board", &request.board).ok());
  CalibrationRunner runner;
  runner.Detect(request);
  runner.WaitIdle();
  EXPECT_EQ(runner.Snapshot()->status.rfind("error: /no/such/folder", 0), 0u)
      << runner.Snapshot()->status;
  EXPECT_EQ(runner.Snapshot()->readiness.level, calib::DataReadiness::Level::kRed);
}

// `fresco gui --calib-images DIR --board B --screenshot X.png` detects and solves before the
// shot; X.png.json lists the Calibration panel, open, with the solved model.
TEST(UiScreenshot, XvfbCalibrationPanelShowsTheSolvedModel) {
  FRESCO_REQUIRE_SHARED_DATA();
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed (apt-get install xvfb xauth): skipped";
  const std::string shot = MakeTempDir("ui-calib-shot") + "/calib.png";
  const auto r = RunFresco({"--xvfb", "gui", "--calib-images", ChessboardLeftImages(), "--board",
                            "chessboard:9x6:0.025", "--model", "opencv4", "--screenshot", shot});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(cv::imread(shot).empty());
  const nlohmann::json list = nlohmann::json::parse(ReadText(shot + ".json"));
  int found = 0;
  for (const auto& panel : list["panels"]) {
    if (panel["title"] != kCalibrationPanelTitle) continue;
    ++found;
    ASSERT_TRUE(panel["open"].get<bool>());
    EXPECT_FALSE(panel["collapsed"].get<bool>());
    const auto& state = panel["state"];
    EXPECT_EQ(state["model"], "opencv4") << state.dump();
    EXPECT_EQ(state["lensmodel"], "LENSMODEL_OPENCV4");
    EXPECT_EQ(state["views"], "13");
    EXPECT_EQ(state["rejected"], "0");
    EXPECT_LT(std::stod(state["rms_px"].get<std::string>()), 0.39);
    EXPECT_NEAR(std::stod(state["fx"].get<std::string>()), 535.92, 0.005 * 535.92);
  }
  EXPECT_EQ(found, 1);
}

TEST(UiCli, CalibImagesNeedsAValidBoard) {
  auto r = RunFresco({"gui", "--calib-images", "/tmp", "--board", "chessboard:9x"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  r = RunFresco({"gui", "--calib-images", "/tmp"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--board"), std::string::npos) << r.err;
}

// The Poses panel's worker with the real `colmap` (skipped when it is not on PATH), on the
// capture of tests/poses/poses_colmap_test.cc with 10 frames instead of 16 (`builtin:blocks`,
// a half orbit; exhaustive matching takes a third of the time) whose given poses are wrong on
// frames 3 and 7 (1 deg) and 5 and 7 (2 % of the scene):
// the run publishes its COLMAP steps, the table flags exactly those frames, "next flagged"
// moves the pipeline to each in turn, the bootstrapped poses (close to the truth) are applied
// as an undoable edit, and `fresco gui --poses bootstrap --poses-model` shows it all under
// Xvfb. COLMAP runs once here; a second run is cancelled during feature extraction.
TEST(PosesRunner, FlagsTheInjectedFramesJumpsToThemAndAppliesTheBootstrap) {
  if (FindProgram("colmap").empty())
    GTEST_SKIP() << "`colmap` is not on PATH (Debian package colmap): skipped";
  constexpr int kFrames = 10;
  const std::string dir = MakeTempDir("ui-poses");
  const std::string capture = dir + "/capture";
  auto r = RunFresco({"synth", "--scene", "builtin:blocks", "--out", capture, "--frames",
                      std::to_string(kFrames), "--size", "480x360", "--supersample", "2", "--seed",
                      "3", "--path", "orbit", "--set", "path.turns=0.5"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  Scene scene;
  ASSERT_TRUE(LoadGltfScene(capture + "/scene.gltf", SceneLoadOptions(), &scene).ok());
  Eigen::Vector3d lo, hi;
  scene.Bounds(&lo, &hi);
  const double scene_size_m = (hi - lo).norm();
  std::vector<PosedImage> truth, given;
  ASSERT_TRUE(ReadColmapImages(capture + "/truth/images.txt", &truth).ok());
  ASSERT_EQ(truth.size(), static_cast<size_t>(kFrames));
  given = truth;
  const std::set<int> rotated = {3, 7}, moved = {5, 7};
  for (int i = 0; i < kFrames; ++i)
    given[i].cam_from_world = testing::Perturbed(
        truth[i].cam_from_world, rotated.count(i) ? 1.0 : 0.0,
        moved.count(i) ? 0.02 * scene_size_m : 0.0, Eigen::Vector3d(1, -2, 0.5 + i));
  ASSERT_TRUE(WriteColmapImages(capture + "/sparse/images.txt", given).ok());

  AppState state;
  ASSERT_TRUE(state.Open(capture + "/project.json").ok());
  const Project before = state.project;
  PipelineRunner runner;
  runner.Restart(state.project);
  runner.WaitIdle();
  PosesRunner poses;
  PosesRequest request;
  request.project = state.project;
  request.out_dir = dir + "/poses";
  request.colmap.colmap.threads = 2;
  NullTextures textures;
  UiContext ui{&state, &runner, nullptr, &textures, nullptr, nullptr, false, &poses};
  ImGuiHeadless imgui;
  std::unique_ptr<Panel> panel;
  for (auto& p : MakePanels())
    if (std::string(p->Title()) == kPosesPanelTitle) panel = std::move(p);
  ASSERT_TRUE(panel);
  EXPECT_FALSE(panel->open);  // opened from the View menu
  panel->open = true;
  poses.Run(request);
  // The UI thread is never blocked: the panel, drawn headless while COLMAP runs, shows the
  // steps as they come.
  std::set<std::string> shown;
  while (true) {
    const bool busy = poses.Snapshot()->busy || !poses.Snapshot()->has_request;
    ui.snapshot = runner.Snapshot();
    ImGuiHeadless::DrawPanel(ui, *panel, ImVec2(1280, 955));
    shown.insert(panel->Report().at("status"));
    if (!busy) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  poses.WaitIdle();
  auto snap = poses.Snapshot();
  ASSERT_TRUE(snap->verified) << snap->status << " " << snap->verify_error;
  EXPECT_TRUE(shown.count("colmap 1/4: feature_extractor")) << shown.size();
  EXPECT_TRUE(shown.count("colmap 3/4: mapper")) << shown.size();
  EXPECT_EQ(snap->registered, kFrames);
  ASSERT_EQ(snap->verify.frames.size(), static_cast<size_t>(kFrames));
  std::set<int> flagged;
  for (size_t i = 0; i < snap->verify.frames.size(); ++i)
    if (snap->verify.frames[i].flagged) flagged.insert(snap->frame_index[i]);
  EXPECT_EQ(flagged, (std::set<int>{3, 5, 7}));
  {  // The 3D view takes COLMAP's path from the verification: a mark per compared frame.
    std::unique_ptr<Panel> view;
    for (auto& p : MakePanels())
      if (std::string(p->Title()) == "3D view") view = std::move(p);
    ASSERT_TRUE(view);
    ui.snapshot = runner.Snapshot();
    ImGuiHeadless::DrawPanel(ui, *view, ImVec2(800, 600));
    EXPECT_EQ(view->Report().at("COLMAP path frames"), std::to_string(kFrames));
  }
  for (int i : rotated) EXPECT_NEAR(snap->verify.frames[i].rotation_error_deg, 1.0, 0.2) << i;
  for (int i : moved)
    EXPECT_NEAR(snap->verify.frames[i].position_error_m, 0.02 * scene_size_m, 0.002 * scene_size_m)
        << i;
  EXPECT_TRUE(fs::is_regular_file(dir + "/poses/verify.json"));  // as `fresco poses verify`
  EXPECT_TRUE(fs::is_regular_file(dir + "/poses/colmap/commands.txt"));
  // Clean frames agree well inside the thresholds (0.5 deg, 1 % of the scene).
  EXPECT_LT(snap->verify.max_unflagged_rotation_error_deg, 0.25);
  EXPECT_LT(snap->verify.max_unflagged_position_error_m, 0.005 * scene_size_m);
  std::cout << "poses runner: clean frames within " << snap->verify.max_unflagged_rotation_error_deg
            << " deg, " << snap->verify.max_unflagged_position_error_m << " m; colmap "
            << snap->colmap_seconds << " s;";
  for (const auto& [step, seconds] : snap->step_seconds) std::cout << " " << step << " " << seconds;
  std::cout << "\n";

  // The panel: "next flagged" moves the pipeline to 3, then 5, then 7.
  for (int i = 0; i < 2; ++i) {
    ui.snapshot = runner.Snapshot();
    ImGuiHeadless::DrawPanel(ui, *panel, ImVec2(1280, 955));
  }
  EXPECT_EQ(panel->Report().at("flagged_frames"), "3,5,7");
  EXPECT_EQ(panel->Report().at("registered"), std::to_string(kFrames));
  for (int expected : {3, 5, 7}) {
    float x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    std::istringstream(panel->Report().at("next_flagged_button")) >> x0 >> y0 >> x1 >> y1;
    ASSERT_GT(x1, x0);
    ImGuiIO& io = ImGui::GetIO();
    io.MousePos = ImVec2((x0 + x1) / 2, (y0 + y1) / 2);
    for (bool down : {false, true, false}) {  // hover, press, release: a click
      io.MouseDown[0] = down;
      ui.snapshot = runner.Snapshot();
      ImGuiHeadless::DrawPanel(ui, *panel, ImVec2(1280, 955));
    }
    io.MousePos = ImVec2(-FLT_MAX, -FLT_MAX);
    runner.WaitIdle();
    EXPECT_EQ(runner.Snapshot()->frame, expected);
    EXPECT_EQ(panel->Report().at("selected_frame"), std::to_string(expected));
  }

  // Apply: the project points at the bootstrapped poses (an undoable, dirty edit).
  ASSERT_TRUE(snap->bootstrapped) << snap->bootstrap_error;
  EXPECT_EQ(snap->aligned_with, "given_poses");
  EXPECT_FALSE(state.dirty);
  ASSERT_TRUE(ApplyBootstrappedPoses(*snap, &state).ok());
  EXPECT_TRUE(state.dirty);
  EXPECT_EQ(state.project.poses, snap->bootstrap_poses);
  EXPECT_EQ(fs::canonical(state.project.Resolve(state.project.poses)),
            fs::canonical(dir + "/poses/sparse/images.txt"));
  std::vector<PosedImage> bootstrapped;
  ASSERT_TRUE(ReadColmapImages(state.project.Resolve(state.project.poses), &bootstrapped).ok());
  ASSERT_EQ(bootstrapped.size(), static_cast<size_t>(kFrames));
  double worst_deg = 0, worst_m = 0;
  for (const PosedImage& b : bootstrapped) {
    const auto t = std::find_if(truth.begin(), truth.end(),
                                [&](const PosedImage& p) { return p.name == b.name; });
    ASSERT_NE(t, truth.end()) << b.name;
    worst_deg = std::max(
        worst_deg, RotationDifferenceDeg(b.cam_from_world.rotation, t->cam_from_world.rotation));
    worst_m = std::max(worst_m, (b.cam_from_world.Centre() - t->cam_from_world.Centre()).norm());
  }
  EXPECT_LT(worst_deg, 0.2);  // the injected errors are gone
  EXPECT_LT(worst_m, 0.01 * scene_size_m);
  std::cout << "bootstrap applied: worst " << worst_deg << " deg, " << worst_m << " m of "
            << scene_size_m << " m\n";
  ui.snapshot = runner.Snapshot();
  ImGuiHeadless::DrawPanel(ui, *panel, ImVec2(1280, 955));
  EXPECT_EQ(panel->Report().at("applied"), "true");
  // Most given poses agree with the reconstruction: the bootstrapped ones are the better.
  EXPECT_EQ(panel->Report().at("bootstrap_better"), "bootstrapped");
  EXPECT_EQ(panel->Report().at("centres_collinear"), "false");
  ASSERT_TRUE(state.Undo());
  EXPECT_EQ(state.project, before);
  // Another project open: the bootstrap does not apply to it.
  PosesSnapshot other = *snap;
  other.request.project.file_path = dir + "/other.json";
  EXPECT_FALSE(ApplyBootstrappedPoses(other, &state).ok());

  // A second run, cancelled while COLMAP runs.
  request.out_dir = dir + "/cancelled";
  poses.Run(request);
  while (true) {  // until COLMAP runs (or the run ended)
    const auto s = poses.Snapshot();
    if (s->request.out_dir == request.out_dir && (s->steps > 0 || !s->busy)) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  poses.Cancel();
  poses.WaitIdle();
  EXPECT_EQ(poses.Snapshot()->status, "cancelled");
  EXPECT_FALSE(poses.Snapshot()->reconstructed);

  // The GL app under Xvfb on the same reconstruction: the panel open with the table.
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0) return;
  const std::string shot = dir + "/poses.png";
  r = RunFresco({"--xvfb", "gui", capture + "/project.json", "--poses", "bootstrap", "--poses-out",
                 dir + "/gui", "--poses-model", dir + "/poses/colmap/sparse_txt/0", "--frames", "5",
                 "--screenshot", shot});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(cv::imread(shot).empty());
  const nlohmann::json list = nlohmann::json::parse(ReadText(shot + ".json"));
  int found = 0;
  for (const auto& p : list["panels"]) {
    if (p["title"] != kPosesPanelTitle) continue;
    ++found;
    ASSERT_TRUE(p["open"].get<bool>());
    EXPECT_EQ(p["state"]["flagged_frames"], "3,5,7") << p.dump();
    EXPECT_EQ(p["state"]["applied"], "true") << p.dump();
  }
  EXPECT_EQ(found, 1);
}

TEST(UiCli, PosesNeedsAProjectAndAKnownMode) {
  auto r = RunFresco({"gui", "--poses", "verify"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("PROJECT"), std::string::npos) << r.err;
  r = RunFresco({"gui", Capture() + "/project.json", "--poses", "check"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("verify or bootstrap"), std::string::npos) << r.err;
  r = RunFresco(
      {"gui", Capture() + "/project.json", "--poses", "verify", "--poses-model", "/no/such/model"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("/no/such/model"), std::string::npos) << r.err;
}

}  // namespace
// The 3D view's up: +Y for a capture of an upright glTF model (cameras level or tilted down
// 30 degrees), the cameras' up for a reconstruction whose frame is the first camera's (up is
// -Y there) or lies on its side; the orbit basis stays right-handed and orthonormal.
TEST(OrbitFrame, UpComesFromTheCapturesCameras) {
  const auto pose = [](const Eigen::Matrix3d& world_from_cam) {
    Rigid3d p;
    p.rotation = Eigen::Quaterniond(world_from_cam.transpose());
    return p;
  };
  // A level camera in a Y-up world looking along -Z: camera x = X, y = -Y, z = -Z.
  Eigen::Matrix3d level;
  level.col(0) = Eigen::Vector3d::UnitX();
  level.col(1) = -Eigen::Vector3d::UnitY();
  level.col(2) = -Eigen::Vector3d::UnitZ();
  const Eigen::Matrix3d tilted =
      Eigen::AngleAxisd(-30 * M_PI / 180, Eigen::Vector3d::UnitX()).toRotationMatrix() * level;
  for (const Eigen::Matrix3d& r : {level, tilted}) {
    const OrbitFrame f = OrbitFrameFromPoses({pose(r), pose(r)});
    EXPECT_EQ(f.up, Eigen::Vector3f::UnitY());
    EXPECT_EQ(f.front, Eigen::Vector3f::UnitZ());
  }
  // COLMAP-like: the world is the first camera's frame (identity), a second camera turned
  // 20 degrees about the vertical: up is -Y, the front towards the cameras (-Z).
  const Eigen::Matrix3d turned =
      Eigen::AngleAxisd(20 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const OrbitFrame colmap = OrbitFrameFromPoses({pose(Eigen::Matrix3d::Identity()), pose(turned)});
  EXPECT_NEAR((colmap.up - Eigen::Vector3f(0, -1, 0)).norm(), 0.0f, 1e-5f);
  EXPECT_LT(colmap.front.z(), -0.9f);
  // On its side: cameras whose up is +X.
  Eigen::Matrix3d side;
  side.col(0) = Eigen::Vector3d::UnitY();
  side.col(1) = -Eigen::Vector3d::UnitX();
  side.col(2) = Eigen::Vector3d::UnitZ();
  const OrbitFrame lying = OrbitFrameFromPoses({pose(side)});
  EXPECT_NEAR((lying.up - Eigen::Vector3f::UnitX()).norm(), 0.0f, 1e-5f);
  for (const OrbitFrame& f : {colmap, lying}) {
    EXPECT_NEAR(f.up.norm(), 1.0f, 1e-5f);
    EXPECT_NEAR(f.front.norm(), 1.0f, 1e-5f);
    EXPECT_NEAR(f.up.dot(f.front), 0.0f, 1e-5f);
    EXPECT_NEAR((f.up.cross(f.front) - f.side).norm(), 0.0f, 1e-5f);
    // Looking from yaw 0, pitch 0 the eye is in front and the screen's up is the frame's up.
    EXPECT_NEAR((OrbitEyeDirection(f, 0, 0) - f.front).norm(), 0.0f, 1e-5f);
    EXPECT_NEAR((OrbitScreenUp(f, 0.3f, 0) - f.up).norm(), 0.0f, 1e-5f);
  }
  // No poses: +Y.
  EXPECT_EQ(OrbitFrameFromPoses({}).up, Eigen::Vector3f::UnitY());
}

}  // namespace fresco
