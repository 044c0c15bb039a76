// The "..." path lists of the whole app, driven headless: where the Calibration panel's
// folder list starts in a freshly started app, and Escape on an open list or menu.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <imgui.h>
#include <imgui_internal.h>

#include "tests/test_support.h"
#include "tests/ui/headless_ui.h"
#include "ui/panels/panels.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using testing::Capture;
using testing::HeadlessApp;
using testing::TypeInto;

constexpr int kKeyEscape = 256;  // GLFW's code

ImGuiWindow* OpenList() {
  for (ImGuiWindow* w : GImGui->Windows)
    if ((w->Flags & ImGuiWindowFlags_Popup) && w->Active) return w;
  return nullptr;
}

// The "..." beside the Calibration panel's folder field, pressed, and the frames that open
// its list.
void BrowseCalibrationFolder(HeadlessApp& app) {
  ImGui::ActivateItem(
      ImHashStr("...", 0, HeadlessApp::Window(kCalibrationPanelTitle)->GetID("##folder")));
  app.Frames(2);
}

std::string CalibrationFolder(HeadlessApp& app) {
  return app.ReportOf(kCalibrationPanelTitle, "folder");
}

// A freshly started app (no folder remembered from an earlier session) that opened a
// project: the Calibration folder's list starts in the project's folder, the last one used,
// not in the folder the app was launched from (its empty field listed "." before). A field
// naming a folder without its '/' lists what is in it (before: the folder around it, with
// that folder as its only entry).
TEST(PathList, TheCalibrationFolderListStartsInTheLastFolderUsed) {
  const std::string project = Capture() + "/project.json";
  HeadlessApp app(project, 0);
  const std::string folder = fs::path(project).lexically_normal().parent_path().string() + "/";
  EXPECT_EQ(app.state.last_folder, folder) << "the project's folder is the last one used";
  app.Find(kCalibrationPanelTitle).open = true;
  app.Frames(2);
  ASSERT_EQ(CalibrationFolder(app), "");
  BrowseCalibrationFolder(app);
  ASSERT_NE(OpenList(), nullptr);
  EXPECT_EQ(CalibrationFolder(app), folder) << "the list starts in the launch folder";
  ImGui::ClosePopupsOverWindow(nullptr, false);
  app.Frames(2);

  TypeInto(app, kCalibrationPanelTitle, "##folder", folder + "frames");
  BrowseCalibrationFolder(app);
  ASSERT_NE(OpenList(), nullptr);
  EXPECT_EQ(CalibrationFolder(app), folder + "frames/") << "the list is not inside the folder";
  ASSERT_NE(OpenList()->GetID("000000.png"), 0u);
}

// Escape on an open list closes it and leaves the field as it was (before: the list stayed
// open; ImGui closes popups on Escape only with keyboard navigation, which the app leaves
// off). A folder opened in the list stays in the field.
TEST(PathList, EscapeClosesAnOpenListLeavingTheField) {
  const std::string project = Capture() + "/project.json";
  HeadlessApp app(project, 0);
  const std::string folder = fs::path(project).lexically_normal().parent_path().string() + "/";
  app.Find(kCalibrationPanelTitle).open = true;
  app.Frames(2);
  TypeInto(app, kCalibrationPanelTitle, "##folder", folder);
  BrowseCalibrationFolder(app);
  ASSERT_NE(OpenList(), nullptr);
  ImGui::ActivateItem(OpenList()->GetID("frames/"));  // opens in place
  app.Frames(2);
  ASSERT_NE(OpenList(), nullptr) << "a folder opens in place";
  ASSERT_EQ(CalibrationFolder(app), folder + "frames/");
  app.input.keys_down[kKeyEscape] = true;
  app.Frame();
  app.input.keys_down[kKeyEscape] = false;
  app.Frames(2);
  EXPECT_EQ(OpenList(), nullptr) << "Escape left the list open";
  EXPECT_EQ(CalibrationFolder(app), folder + "frames/") << "Escape changed the field";
}

// Escape closes what is open on top, one at a time: in File > Open..., the "..." list (its
// field as the list left it), then the submenu, then the File menu (before: Escape closed no
// menu or list at all).
TEST(PathList, EscapeClosesTheListOrMenuOnTopOneAtATime) {
  HeadlessApp app(Capture() + "/project.json", 0);
  const float line = ImGui::GetFrameHeight();
  app.Click(ImVec2(15, line / 2));  // "File" in the menu bar
  ImGuiWindow* file = ImGui::FindWindowByName("##Menu_00");
  ASSERT_NE(file, nullptr);
  const float item = ImGui::GetTextLineHeight() + ImGui::GetStyle().ItemSpacing.y;
  app.MouseTo(file->Pos.x + 30, file->DC.CursorStartPos.y + 1.5f * item);  // "Open..."
  app.Frames(3);
  ImGuiWindow* open = ImGui::FindWindowByName("##Menu_01");
  ASSERT_NE(open, nullptr);
  ImGui::ActivateItem(ImHashStr("...", 0, open->GetID("##menu_open")));
  app.Frames(2);
  ASSERT_EQ(GImGui->OpenPopupStack.Size, 3) << "File, Open... and the list";
  const std::string listed = app.ui.menu_path;
  EXPECT_EQ(listed, app.state.last_folder);
  app.MouseTo(800, 600);  // over the 3D view, off the menus
  app.Frames(2);
  for (const int left : {2, 1, 0}) {
    app.input.keys_down[kKeyEscape] = true;
    app.Frame();
    app.input.keys_down[kKeyEscape] = false;
    app.Frames(2);
    EXPECT_EQ(GImGui->OpenPopupStack.Size, left);
  }
  EXPECT_EQ(app.ui.menu_path, listed);
}

}  // namespace
}  // namespace fresco
