// The app's pure logic, no ImGui frame and no display: natural name order, stable group
// colours, zoom and pan, window clamping, the input queue, pixel readouts, colour scales,
// the message when stored groups are split back apart, and New project on live sources.
#include <fstream>

#include <gtest/gtest.h>
#include <imgui.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "tests/test_support.h"
#include "ui/core/app_state.h"
#include "ui/core/calibration_runner.h"
#include "ui/core/colour_scale.h"
#include "ui/core/group_colour.h"
#include "ui/core/image_view.h"
#include "ui/core/input_queue.h"
#include "ui/core/layout.h"
#include "ui/core/layout_file.h"
#include "ui/core/natural_sort.h"
#include "ui/core/ui_scale.h"
#include "ui/core/zoom_pan.h"
#include "ui/panels/panels.h"

namespace fresco {
namespace {

TEST(NaturalSort, NumbersCompareByValue) {
  std::vector<std::string> names = {"warped_b19", "visible_b2", "warped_b2", "warped_b10",
                                    "warped_b02", "depth",      "warped_b1"};
  SortNaturally(&names);
  EXPECT_EQ(names, (std::vector<std::string>{"depth", "visible_b2", "warped_b1", "warped_b2",
                                             "warped_b02", "warped_b10", "warped_b19"}));
  EXPECT_TRUE(NaturalLess("b2", "b19"));
  EXPECT_FALSE(NaturalLess("b19", "b2"));
  EXPECT_FALSE(NaturalLess("b2", "b2"));
  EXPECT_TRUE(NaturalLess("b", "b0"));
  EXPECT_TRUE(NaturalLess("frame9.png", "frame10.png"));
  EXPECT_TRUE(NaturalLess("a99999999999999999999", "a100000000000000000000"));  // no overflow
}

// Picked triangles are drawn in a colour no group has: at least 0.7 (in RGB 0..1) from every
// colour a group can get; the yellow they were drawn in was 0.15 from the nearest.
TEST(GroupColour, PickedTrianglesAreFarFromEveryGroupColour) {
  EXPECT_EQ(AllGroupColours().size(), 3600u);
  EXPECT_GT(DistanceToNearestGroupColour(kPickedRgb), 0.7f);
  EXPECT_GT(DistanceToNearestGroupColour(kPickedStripeRgb), 0.7f);
  EXPECT_LT(DistanceToNearestGroupColour({1.0f, 0.85f, 0.1f}), 0.3f) << "the old yellow";
  for (int key = 0; key < 2000; ++key) {
    const auto c = GroupColour(key);
    EXPECT_LT(DistanceToNearestGroupColour(c), 1e-6f) << key;
  }
}

TEST(GroupColour, KeyIsTheLowestTriangleAndColoursDiffer) {
  EXPECT_EQ(StableGroupKey(GroupSpec{{7, 3, 9}}), 3);
  EXPECT_EQ(StableGroupKey(GroupSpec{}), -1);
  const auto a = GroupColour(3), b = GroupColour(4), a2 = GroupColour(3);
  EXPECT_EQ(a, a2);
  float diff = 0;
  for (int c = 0; c < 3; ++c) {
    EXPECT_GE(a[c], 0.25f);
    EXPECT_LE(a[c], 0.9f + 1e-6f);
    diff += std::abs(a[c] - b[c]);
  }
  EXPECT_GT(diff, 0.05f) << "neighbouring keys should not look alike";
  // A merge keeps the untouched groups' keys, and the merged group takes the lower one.
  const std::vector<GroupSpec> before = {{{0, 1}}, {{2, 3}}, {{4, 5}}, {{6, 7}}};
  std::vector<GroupSpec> merged;
  ASSERT_TRUE(MergeGroups(before, 8, {1, 3}, &merged).ok());
  std::vector<int> keys = StableGroupKeys(merged);
  std::sort(keys.begin(), keys.end());
  EXPECT_EQ(keys, (std::vector<int>{0, 2, 4}));
}

TEST(ZoomPan, ZoomKeepsThePointUnderTheCursorAndPanMoves) {
  const ZoomPanView v{200, 100, 400, 200};  // fit: 0.5 view px per image px
  ZoomPan zp;
  EXPECT_FLOAT_EQ(zp.Scale(v.view_w, v.view_h, v.image_w, v.image_h), 0.5f);
  int col = 0, row = 0;
  ASSERT_TRUE(PixelUnder(zp, v, 50, 25, &col, &row));
  EXPECT_EQ(col, 100);
  EXPECT_EQ(row, 50);
  float ix = 0, iy = 0, x = 0, y = 0;
  ViewToImage(zp, v, 50, 25, &ix, &iy);
  ZoomPan zoomed;
  ZoomAbout(zp, v, 50, 25, 4.0f, &zoomed);
  EXPECT_FLOAT_EQ(zoomed.zoom, 4.0f);
  ImageToView(zoomed, v, ix, iy, &x, &y);
  EXPECT_NEAR(x, 50, 1e-3);
  EXPECT_NEAR(y, 25, 1e-3);
  ASSERT_TRUE(PixelUnder(zoomed, v, 51, 25, &col, &row));  // one view px = 0.5 image px now
  EXPECT_EQ(col, 100);
  // A drag of 20 view pixels right shows what was 10 image pixels to the left.
  ZoomPan panned;
  PanBy(zoomed, v, 20, 0, &panned);
  ViewToImage(panned, v, 70, 25, &x, &y);
  EXPECT_NEAR(x, ix, 1e-3);
  // Zooming out fully fits the image again; never beyond the limits.
  ZoomPan out;
  ZoomAbout(panned, v, 10, 10, 1e-3f, &out);
  EXPECT_FLOAT_EQ(out.zoom, 1.0f);
  EXPECT_LT(out.centre_x, 0);
  ZoomAbout(zp, v, 10, 10, 1e6f, &out);
  EXPECT_FLOAT_EQ(out.zoom, ZoomPan::kMaxZoom);
  EXPECT_FALSE(PixelUnder(zp, v, 250, 25, &col, &row));  // right of the image
}

TEST(Layout, TitleBarStaysBelowTheMenuBarAndOnScreen) {
  const LayoutBand band{1280, 800, 19, 24};
  LayoutRect r = KeepTitleBarReachable({100, -40, 300, 200}, band, 19);
  EXPECT_EQ(r.y, 19);
  EXPECT_EQ(r.x, 100);
  r = KeepTitleBarReachable({1270, 900, 300, 200}, band, 19);
  EXPECT_EQ(r.y, 800 - 24 - 19);
  EXPECT_EQ(r.x, 1280 - 48);
  r = KeepTitleBarReachable({-500, 300, 300, 200}, band, 19);
  EXPECT_EQ(r.x, 48 - 300);
  const LayoutRect inside{10, 30, 300, 200};
  r = KeepTitleBarReachable(inside, band, 19);
  EXPECT_EQ(r.x, inside.x);
  EXPECT_EQ(r.y, inside.y);
}

InputEvent Key(int code, bool down) {
  InputEvent e;
  e.kind = InputEvent::Kind::kKey;
  e.code = code;
  e.down = down;
  return e;
}
InputEvent Button(bool down) {
  InputEvent e;
  e.kind = InputEvent::Kind::kMouseButton;
  e.down = down;
  return e;
}
InputEvent Move(float x, float y) {
  InputEvent e;
  e.kind = InputEvent::Kind::kMouseMove;
  e.x = x, e.y = y;
  return e;
}

TEST(InputQueue, ATapWithinOneFrameIsSeenOverTwoFrames) {
  InputQueue queue;
  InputState state;
  queue.Push(Key(kKeyLeftControl, true));
  queue.Push(Key('S', true));
  queue.Push(Key('S', false));
  queue.Push(Key(kKeyLeftControl, false));
  EXPECT_EQ(queue.NextFrame(&state), 2);  // ctrl and S down; S's release waits
  EXPECT_TRUE(state.keys_down['S']);
  EXPECT_TRUE(state.keys_down[kKeyLeftControl]);
  EXPECT_EQ(queue.NextFrame(&state), 2);
  EXPECT_FALSE(state.keys_down['S']);
  EXPECT_FALSE(state.keys_down[kKeyLeftControl]);
  EXPECT_EQ(queue.pending(), 0u);
  EXPECT_EQ(queue.NextFrame(&state), 0);
}

// Text typed right after a click lands in the frame after the click (the field clicked has
// the focus by then), and a key pressed after typing comes after the text.
TEST(InputQueue, TextTypedRightAfterAClickWaitsForTheClickAndKeysForTheText) {
  InputQueue queue;
  InputState state;
  const auto typed = [](unsigned int c) {
    InputEvent e;
    e.kind = InputEvent::Kind::kChar;
    e.code = static_cast<int>(c);
    return e;
  };
  queue.Push(Button(true));
  queue.Push(Button(false));
  queue.Push(typed('a'));
  queue.Push(typed('b'));
  queue.Push(Key('X', true));
  EXPECT_EQ(queue.NextFrame(&state), 1);  // the press
  EXPECT_TRUE(state.chars.empty());
  EXPECT_EQ(queue.NextFrame(&state), 1);  // the release
  EXPECT_TRUE(state.chars.empty());
  EXPECT_EQ(queue.NextFrame(&state), 2);  // the text, in order; the key after it waits
  EXPECT_EQ(state.chars, (std::vector<unsigned int>{'a', 'b'}));
  EXPECT_FALSE(state.keys_down['X']);
  EXPECT_EQ(queue.NextFrame(&state), 1);
  EXPECT_TRUE(state.chars.empty());  // per frame
  EXPECT_TRUE(state.keys_down['X']);
  ImGui::CreateContext();
  state.chars = {'z'};
  CopyToImGui(state, &ImGui::GetIO());
  ASSERT_EQ(ImGui::GetIO().InputQueueCharacters.Size, 1);
  EXPECT_EQ(ImGui::GetIO().InputQueueCharacters[0], 'z');
  ImGui::DestroyContext();
}

TEST(InputQueue, AFastDragIsPressMovesAndReleaseInFramesOfTheirOwn) {
  InputQueue queue;
  InputState state;
  queue.Push(Move(10, 10));
  queue.Push(Button(true));
  queue.Push(Move(20, 10));
  queue.Push(Move(30, 10));
  queue.Push(Button(false));
  InputEvent wheel;
  wheel.kind = InputEvent::Kind::kWheel;
  wheel.y = 1;
  queue.Push(wheel);
  queue.Push(wheel);
  // Frame 1: moved to the press point; the press itself waits (a button after a move).
  queue.NextFrame(&state);
  EXPECT_EQ(state.mouse_x, 10);
  EXPECT_FALSE(state.mouse_down[0]);
  queue.NextFrame(&state);  // the press, where it happened
  EXPECT_TRUE(state.mouse_down[0]);
  EXPECT_EQ(state.mouse_x, 10);
  queue.NextFrame(&state);  // the drag, still pressed
  EXPECT_TRUE(state.mouse_down[0]);
  EXPECT_EQ(state.mouse_x, 30);
  queue.NextFrame(&state);  // the release, then the wheel in the same frame
  EXPECT_FALSE(state.mouse_down[0]);
  EXPECT_EQ(state.wheel_y, 2);
  queue.NextFrame(&state);
  EXPECT_EQ(state.wheel_y, 0);  // per frame
  // Into ImGui: position, buttons, keys and modifiers.
  ImGui::CreateContext();
  state.keys_down[kKeyRightControl] = true;
  state.mouse_down[1] = true;
  CopyToImGui(state, &ImGui::GetIO());
  EXPECT_TRUE(ImGui::GetIO().KeyCtrl);
  EXPECT_FALSE(ImGui::GetIO().KeyShift);
  EXPECT_TRUE(ImGui::GetIO().MouseDown[1]);
  EXPECT_EQ(ImGui::GetIO().MousePos.x, 30);
  ImGui::DestroyContext();
}

// Ctrl held for a click, all between two frames: the release (where ImGui's selectables
// act) still sees ctrl, and ctrl's release comes a frame later.
TEST(InputQueue, ACtrlClickWithinOneFrameKeepsCtrlForTheRelease) {
  InputQueue queue;
  InputState state;
  queue.Push(Key(kKeyLeftControl, true));
  queue.Push(Move(5, 5));
  queue.Push(Button(true));
  queue.Push(Button(false));
  queue.Push(Key(kKeyLeftControl, false));
  bool released_with_ctrl = false;
  for (int frame = 0; frame < 8 && queue.pending() > 0; ++frame) {
    const bool was_down = state.mouse_down[0];
    queue.NextFrame(&state);
    if (was_down && !state.mouse_down[0]) released_with_ctrl = state.keys_down[kKeyLeftControl];
  }
  EXPECT_EQ(queue.pending(), 0u);
  EXPECT_TRUE(released_with_ctrl);
  EXPECT_FALSE(state.keys_down[kKeyLeftControl]);
  EXPECT_EQ(state.mouse_x, 5);
}

TEST(ImageView, PixelReadoutNamesPositionAndChannels) {
  cv::Mat bgr(4, 5, CV_8UC3, cv::Scalar(10, 20, 30));
  EXPECT_EQ(DescribePixel(bgr, 2, 3), "x 2 y 3: B 10 G 20 R 30");
  cv::Mat grey(4, 5, CV_8UC1, cv::Scalar(7));
  EXPECT_EQ(DescribePixel(grey, 0, 0), "x 0 y 0: 7");
  cv::Mat depth(4, 5, CV_32FC1, cv::Scalar(2.5));
  EXPECT_EQ(DescribePixel(depth, 4, 1), "x 4 y 1: 2.5");
  EXPECT_EQ(DescribePixel(bgr, 5, 0), "");
  EXPECT_EQ(DescribePixel(bgr, -1, 0), "");
}

TEST(ColourScale, FalseColouredImagesHaveAScale) {
  ColourScale scale;
  ASSERT_TRUE(FalseColourScaleOf("depth", "depth", &scale));
  EXPECT_EQ(scale.colormap, cv::COLORMAP_VIRIDIS);
  ASSERT_TRUE(FalseColourScaleOf("refine", "residual_before_b3", &scale));
  EXPECT_EQ(scale.colormap, cv::COLORMAP_INFERNO);
  EXPECT_FALSE(FalseColourScaleOf("warp", "warped_b3", &scale));
  EXPECT_FALSE(FalseColourScaleOf("paint", "painted_b0", &scale));
}

TEST(GroupingSplitBack, SaysWhichStoredGroupWasSplitAndWhy) {
  const std::vector<GroupSpec> stored = {{{0, 1, 2, 3}}, {{4, 5}}};
  EXPECT_EQ(DescribeGroupsSplitBack(stored, stored, 6), "");
  const std::vector<GroupSpec> built = {{{0, 1}}, {{4, 5}}, {{2, 3}}};
  const std::string message = DescribeGroupsSplitBack(stored, built, 6);
  EXPECT_NE(message.find("split back apart"), std::string::npos) << message;
  // Named by the numbers the Grouping panel lists after the split: 0 and 2.
  EXPECT_NE(message.find("now groups 0 and 2"), std::string::npos) << message;
  EXPECT_NE(message.find("became 2 buffers"), std::string::npos) << message;
  EXPECT_NE(message.find("fold over"), std::string::npos) << message;
}

// The scale of a dense monitor times the user's: the font built at the next whole multiple
// of 13 pixels and shown at the scale, the style's sizes scaled; rebuilt only on a change.
TEST(UiScaleTest, FontsAreBuiltAtTheScaleAndRebuiltOnlyWhenItChanges) {
  EXPECT_EQ(FontAtlasMultiple(0.75f), 1);
  EXPECT_EQ(FontAtlasMultiple(1.0f), 1);
  EXPECT_EQ(FontAtlasMultiple(1.5f), 2);
  EXPECT_EQ(FontAtlasMultiple(2.0f), 2);
  EXPECT_EQ((UiScale{2.0f, 1.5f}.Total()), 3.0f);
  EXPECT_EQ((UiScale{4.0f, 2.0f}.Total()), kMaxUiScale);
  ImGui::CreateContext();
  const float padding = ImGui::GetStyle().FramePadding.y;
  float applied = 0;
  EXPECT_TRUE(ApplyUiScale(1.5f, &applied));
  EXPECT_EQ(applied, 1.5f);
  EXPECT_EQ(ImGui::GetIO().Fonts->Fonts[0]->FontSize, 26.0f);
  EXPECT_EQ(ImGui::GetIO().FontGlobalScale, 0.75f);
  EXPECT_EQ(ImGui::GetStyle().FramePadding.y, std::floor(1.5f * padding));
  EXPECT_FALSE(ApplyUiScale(1.5f, &applied));  // unchanged: nothing rebuilt
  EXPECT_TRUE(ApplyUiScale(1.0f, &applied));
  EXPECT_EQ(ImGui::GetIO().Fonts->Fonts[0]->FontSize, 13.0f);
  EXPECT_EQ(ImGui::GetStyle().FramePadding.y, padding);  // from the dark style, not compounded
  ImGui::DestroyContext();
}

TEST(LayoutFile, SplittersPlacesAndFontScaleSurviveARestart) {
  const std::string dir = testing::MakeTempDir("ui-layout");
  SavedLayout saved;
  std::vector<float> fractions = saved.layout.Fractions();
  ASSERT_GE(fractions.size(), 10u);
  fractions[0] = 0.31f;
  fractions.back() = 0.66f;
  saved.layout.SetFractions(fractions);
  ASSERT_TRUE(saved.layout.Swap("3D view", "Grouping"));  // places swapped too
  saved.font_scale = 1.5f;
  ASSERT_TRUE(SaveLayoutFile(dir + "/cfg/layout.json", saved).ok());
  SavedLayout loaded;
  ASSERT_TRUE(LoadLayoutFile(dir + "/cfg/layout.json", &loaded).ok());
  EXPECT_EQ(loaded.layout.Fractions(), fractions);
  EXPECT_EQ(loaded.layout.Panels(), saved.layout.Panels());
  EXPECT_NE(loaded.layout.Panels(), DefaultTileLayout().Panels());
  EXPECT_EQ(loaded.font_scale, 1.5f);
  // Panels that are not a reordering of the app's (another version's) are ignored.
  std::ofstream(dir + "/renamed.json")
      << R"({"fractions": [], "panels": ["3D view", "Gone"], "font_scale": 1})";
  SavedLayout renamed;
  ASSERT_TRUE(LoadLayoutFile(dir + "/renamed.json", &renamed).ok());
  EXPECT_EQ(renamed.layout.Panels(), DefaultTileLayout().Panels());
  // No file: the defaults, no error.
  SavedLayout fresh;
  EXPECT_TRUE(LoadLayoutFile(dir + "/none.json", &fresh).ok());
  EXPECT_EQ(fresh.layout.Fractions(), DefaultTileLayout().Fractions());
  // Another arrangement's fractions are ignored; a damaged file is an error naming it.
  std::ofstream(dir + "/other.json") << R"({"fractions": [0.5, 0.5], "font_scale": 1.25})";
  ASSERT_TRUE(LoadLayoutFile(dir + "/other.json", &fresh).ok());
  EXPECT_EQ(fresh.layout.Fractions(), DefaultTileLayout().Fractions());
  EXPECT_EQ(fresh.font_scale, 1.25f);
  std::ofstream(dir + "/bad.json") << "{\"fractions\": ";
  const Status bad = LoadLayoutFile(dir + "/bad.json", &fresh);
  EXPECT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("bad.json"), std::string::npos) << bad.message();
  std::ofstream(dir + "/scale.json") << R"({"fractions": [], "font_scale": 40})";
  EXPECT_FALSE(LoadLayoutFile(dir + "/scale.json", &fresh).ok());
}

// The calibration's default file: beside the project (named after the image folder), or
// beside the image folder with no project; never inside the image folder.
TEST(CalibrationSavePath, BesideTheProjectNeverInsideTheImages) {
  EXPECT_EQ(DefaultCameraModelPath("/data/rig/cam0", "/work/proj/project.json"),
            "/work/proj/cam0.cameramodel");
  EXPECT_EQ(DefaultCameraModelPath("/data/rig/cam0/", "/work/proj/project.json"),
            "/work/proj/cam0.cameramodel");
  EXPECT_EQ(DefaultCameraModelPath("/data/rig/cam0", ""), "/data/rig/cam0.cameramodel");
}

// Attach to project: a version-1 project's camera, relative to its folder when below it;
// undo restores the previous one; a version-2 project's chosen stream.
TEST(CalibrationAttach, SetsTheProjectCameraAndUndoRestoresIt) {
  AppState state;
  EXPECT_FALSE(AttachCameraToProject("/p/cam.cameramodel", 0, &state).ok());  // no project
  state.has_project = true;
  state.project.file_path = "/p/project.json";
  state.project.camera = "old/cameras.txt";
  ASSERT_TRUE(AttachCameraToProject("/p/calib/cam0.cameramodel", 0, &state).ok());
  EXPECT_EQ(state.project.camera, "calib/cam0.cameramodel");
  EXPECT_TRUE(state.dirty);
  ASSERT_TRUE(AttachCameraToProject("/elsewhere/cam1.cameramodel", 0, &state).ok());
  EXPECT_EQ(state.project.camera, "/elsewhere/cam1.cameramodel");
  ASSERT_TRUE(state.Undo());
  ASSERT_TRUE(state.Undo());
  EXPECT_EQ(state.project.camera, "old/cameras.txt");

  state.project.fresco_version = 2;
  state.project.camera.clear();
  state.project.streams = {{"a/cameras.txt", "a/frames/", "a/images.txt"},
                           {"b/cameras.txt", "b/frames/", "b/images.txt"}};
  EXPECT_FALSE(AttachCameraToProject("/p/b.cameramodel", 2, &state).ok());
  ASSERT_TRUE(AttachCameraToProject("/p/b.cameramodel", 1, &state).ok());
  EXPECT_EQ(state.project.streams[1].camera, "b.cameramodel");
  EXPECT_EQ(state.project.streams[0].camera, "a/cameras.txt");
}

// New project with a live video and pose feed: stored as typed (nothing to open now), the
// mesh and camera relative to the file; a second Create on the same path is refused.
TEST(NewProject, LiveSourcesAreKeptAsTypedAndAnExistingFileIsNotReplaced) {
  const std::string dir = testing::MakeTempDir("new-project");
  NewProjectForm form;
  form.scene = testing::SourceDir() + "/projects/cube-room/scene.gltf";
  form.camera = testing::SourceDir() + "/projects/static-cam/cameras.txt";
  form.video = "udp://127.0.0.1:5600";
  form.poses = "tcp://127.0.0.1:7000";
  form.project_file = dir + "/live/project.json";
  Project made;
  const Status s = BuildNewProject(form, &made);
  ASSERT_TRUE(s.ok()) << s.message();
  Project loaded;
  ASSERT_TRUE(LoadProject(form.project_file, {}, &loaded).ok());
  EXPECT_EQ(loaded, made);
  EXPECT_EQ(loaded.video, form.video);
  EXPECT_EQ(loaded.poses, form.poses);
  EXPECT_NE(loaded.camera.front(), '/') << loaded.camera;
  EXPECT_EQ(loaded.Resolve(loaded.camera), form.camera);
  const std::string text = testing::ReadText(form.project_file);
  const Status again = BuildNewProject(form, &made);
  EXPECT_EQ(again.message(), form.project_file + ": exists already (open it with Open)");
  EXPECT_EQ(testing::ReadText(form.project_file), text);
  form.project_file.clear();
  EXPECT_FALSE(BuildNewProject(form, &made).ok());
}

}  // namespace
}  // namespace fresco
