// The tool panels (Poses, Calibration, New project) driven headless from the View menu: they
// open as tabs in the stage row's place below the 3D view, never over another panel; a
// second tool opens beside the first as a tab and the first keeps its tick; a click on a tab
// brings it back; maximising the 3D view hides them; and a flagged frame chosen in the
// Poses panel shows in the 3D view and the input frame beside it.
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <imgui.h>
#include <imgui_internal.h>

#include "pipeline/core/poses.h"
#include "tests/poses/perturbed_pose.h"
#include "tests/test_support.h"
#include "tests/ui/headless_ui.h"
#include "ui/core/poses_runner.h"
#include "ui/panels/panels.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using testing::Capture;
using testing::HeadlessApp;

bool Shown(const std::string& title) {
  ImGuiWindow* w = ImGui::FindWindowByName(PanelWindowId(title).c_str());
  return w && w->Active;
}

// The shown panels whose windows overlap (each pair once), "" when none do.
std::string Overlaps(HeadlessApp& app) {
  std::vector<ImGuiWindow*> shown;
  for (const auto& p : app.panels)
    if (Shown(p->Title()))
      shown.push_back(ImGui::FindWindowByName(PanelWindowId(p->Title()).c_str()));
  std::string overlaps;
  for (size_t i = 0; i < shown.size(); ++i)
    for (size_t j = i + 1; j < shown.size(); ++j) {
      const ImRect a = shown[i]->Rect(), b = shown[j]->Rect();
      const float w = std::min(a.Max.x, b.Max.x) - std::max(a.Min.x, b.Min.x);
      const float h = std::min(a.Max.y, b.Max.y) - std::max(a.Min.y, b.Min.y);
      if (w > 0.5f && h > 0.5f)
        overlaps += std::string(shown[i]->Name) + " / " + shown[j]->Name + "; ";
    }
  return overlaps;
}

// View > `title`: the menu opened with a click on "View", the item chosen.
void ToggleFromViewMenu(HeadlessApp& app, const std::string& title) {
  const float line = ImGui::GetFrameHeight();
  app.Click(ImVec2(ImGui::CalcTextSize("File").x + ImGui::CalcTextSize("Edit").x + 50, line / 2));
  ImGuiWindow* view = ImGui::FindWindowByName("##Menu_00");
  ASSERT_NE(view, nullptr);
  ASSERT_TRUE(view->Active) << "the View menu is open";
  ImGui::ActivateItem(view->GetID(title.c_str()));
  app.Frames(3);
}

void ClickTab(HeadlessApp& app, const std::string& name) {
  const auto it = app.ui.tabs_drawn.find(name);
  ASSERT_NE(it, app.ui.tabs_drawn.end()) << "no tab " << name;
  app.Click(ImVec2(it->second.x + it->second.w / 2, it->second.y + it->second.h / 2));
  app.Frames(2);
}

TEST(UiToolTabs, ToolPanelsOpenAsTabsBelowThe3DViewNeverOverIt) {
  HeadlessApp app(Capture() + "/project.json", 2);
  PosesRunner poses;
  app.ui.poses = &poses;
  const ImRect view_before = HeadlessApp::Window("3D view")->Rect();
  ToggleFromViewMenu(app, kPosesPanelTitle);
  ASSERT_TRUE(app.Find(kPosesPanelTitle).open);
  EXPECT_TRUE(Shown(kPosesPanelTitle));
  EXPECT_TRUE(Shown("3D view"));
  EXPECT_TRUE(Shown("Input frame")) << "the frame a verdict is about, beside the table";
  EXPECT_EQ(Overlaps(app), "");
  ImGuiWindow* poses_window = HeadlessApp::Window(kPosesPanelTitle);
  const ImRect view = HeadlessApp::Window("3D view")->Rect();
  EXPECT_GE(poses_window->Pos.y, view.Max.y) << "below the 3D view";
  EXPECT_GT(poses_window->Size.x, 0.5f * (view.Max.x - view.Min.x));
  EXPECT_GT(poses_window->Size.y, 0.5f * (view_before.Max.y - view_before.Min.y))
      << "taller than the stage row: room for the plots and the table";
  EXPECT_TRUE(poses_window->Flags & ImGuiWindowFlags_NoCollapse)
      << "a title never left over another";
  EXPECT_FALSE(Shown("Stage: paint")) << "behind the Stages tab";

  // Calibration opens as another tab; Poses stays open (its tick) behind its tab.
  ToggleFromViewMenu(app, kCalibrationPanelTitle);
  EXPECT_TRUE(app.Find(kPosesPanelTitle).open) << "opening Calibration took Poses' tick";
  EXPECT_TRUE(Shown(kCalibrationPanelTitle));
  EXPECT_FALSE(Shown(kPosesPanelTitle));
  EXPECT_EQ(Overlaps(app), "");
  for (const std::string tab : {"Stages", kPosesPanelTitle, kCalibrationPanelTitle})
    EXPECT_TRUE(app.ui.tabs_drawn.count(tab)) << tab;
  ClickTab(app, kPosesPanelTitle);
  EXPECT_TRUE(Shown(kPosesPanelTitle));
  EXPECT_FALSE(Shown(kCalibrationPanelTitle));
  EXPECT_TRUE(app.Find(kCalibrationPanelTitle).open);
  ClickTab(app, "Stages");
  EXPECT_TRUE(Shown("Stage: paint"));
  EXPECT_FALSE(Shown(kPosesPanelTitle));
  EXPECT_EQ(Overlaps(app), "");

  // View > Maximise > 3D view: the view alone, nothing over it.
  app.ui.layout.ToggleMaximised("3D view");
  app.Frames(2);
  for (const auto& p : app.panels)
    EXPECT_EQ(Shown(p->Title()), std::string(p->Title()) == "3D view") << p->Title();
  EXPECT_TRUE(app.ui.tabs_drawn.empty());
  app.ui.layout.ToggleMaximised("3D view");
  app.Frames(2);

  // Closing the tools gives the row back to the stages, without tabs.
  ToggleFromViewMenu(app, kPosesPanelTitle);
  ToggleFromViewMenu(app, kCalibrationPanelTitle);
  EXPECT_TRUE(Shown("Stage: paint"));
  EXPECT_TRUE(app.ui.tabs_drawn.empty());
  EXPECT_EQ(HeadlessApp::Window("3D view")->Rect().Max.y, view_before.Max.y);
}

// A verification of the capture's poses against its truth (as a COLMAP model from an earlier
// run), one frame's given pose rotated by 2 degrees: "next flagged" in the Poses panel moves
// the pipeline there, and the 3D view and the input frame show it beside the table.
TEST(UiToolTabs, AFlaggedFrameChosenInPosesShowsInThe3DViewAndInputFrameBesideIt) {
  const std::string dir = testing::MakeTempDir("ui-tool-tabs") + "/capture";
  fs::copy(Capture(), dir, fs::copy_options::recursive);
  std::vector<PosedImage> given;
  ASSERT_TRUE(ReadColmapImages(dir + "/sparse/images.txt", &given).ok());
  ASSERT_GE(given.size(), 8u);
  constexpr int kWrong = 6;
  given[kWrong].cam_from_world =
      testing::Perturbed(given[kWrong].cam_from_world, 2.0, 0.0, Eigen::Vector3d(1, -2, 0.5));
  ASSERT_TRUE(WriteColmapImages(dir + "/sparse/images.txt", given).ok());

  HeadlessApp app(dir + "/project.json", 1);
  PosesRunner poses;
  app.ui.poses = &poses;
  PosesRequest request;
  request.project = app.state.project;
  request.out_dir = dir + "/../poses";
  request.colmap.existing_model = dir + "/truth";
  poses.Run(request);
  poses.WaitIdle();
  ASSERT_TRUE(poses.Snapshot()->verified)
      << poses.Snapshot()->status << " " << poses.Snapshot()->verify_error;
  ToggleFromViewMenu(app, kPosesPanelTitle);
  app.Frames(2);
  ASSERT_EQ(app.ReportOf(kPosesPanelTitle, "flagged_frames"), std::to_string(kWrong));
  float x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  std::istringstream(app.ReportOf(kPosesPanelTitle, "next_flagged_button")) >> x0 >> y0 >> x1 >> y1;
  ASSERT_GT(x1, x0);
  app.Click(ImVec2((x0 + x1) / 2, (y0 + y1) / 2));
  app.runner.WaitIdle();
  app.Frames(2);
  EXPECT_EQ(app.runner.Snapshot()->frame, kWrong);
  EXPECT_EQ(app.ReportOf(kPosesPanelTitle, "selected_frame"), std::to_string(kWrong));
  for (const char* beside : {"3D view", "Input frame"}) EXPECT_TRUE(Shown(beside)) << beside;
  EXPECT_EQ(app.ReportOf("3D view", "COLMAP path frames"), std::to_string(given.size()));
  EXPECT_EQ(Overlaps(app), "");
}

}  // namespace
}  // namespace fresco
