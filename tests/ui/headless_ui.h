// The app without a display, for tests: null image and viewport backends (no GL) and a
// Dear ImGui context that draws the app frame headless.
#pragma once

#include <cstdint>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <imgui.h>
#include <imgui_internal.h>

#include "tests/test_support.h"
#include "ui/core/app_frame.h"
#include "ui/core/calibration_runner.h"
#include "ui/core/input_queue.h"
#include "ui/core/panel.h"
#include "ui/panels/panels.h"

namespace fresco::testing {

// A 12-frame 160x120 capture of the cube room (`fresco synth`), made once per test program.
inline std::string Capture() {
  static const std::string dir = [] {
    const std::string d = MakeTempDir("ui") + "/capture";
    const auto r = RunFresco({"synth", "--scene", "builtin:cube-room", "--out", d, "--frames", "12",
                              "--size", "160x120", "--seed", "3"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return d;
  }();
  return dir;
}

class NullTextures : public ImageTextures {
 public:
  ImTextureID Get(const std::string& key, const cv::Mat& image, uint64_t) override {
    ++requests;
    keys.insert(key);
    EXPECT_FALSE(image.empty()) << key;
    return reinterpret_cast<ImTextureID>(static_cast<intptr_t>(1));
  }
  int requests = 0;
  std::set<std::string> keys;
};

class NullViewport : public ViewportRenderer {
 public:
  ImTextureID Render(const RunnerSnapshot& snapshot, const AppState&, ViewportView* view, int w,
                     int h) override {
    ++renders;
    EXPECT_TRUE(snapshot.geometry != nullptr);
    EXPECT_GT(w, 0);
    EXPECT_GT(h, 0);
    view->target_set = true;
    return reinterpret_cast<ImTextureID>(static_cast<intptr_t>(2));
  }
  int Pick(int, int) override { return 0; }
  int renders = 0;
};

struct ImGuiHeadless {
  ImGuiHeadless() {
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.DisplaySize = ImVec2(1600, 1000);
    io.DeltaTime = 1.0f / 60;
    io.IniFilename = nullptr;
    ConfigureImGui(&io);
    // The keys as ImGui's GLFW backend maps them (GLFW key codes).
    io.KeyMap[ImGuiKey_Space] = 32;
    io.KeyMap[ImGuiKey_LeftArrow] = 263;
    io.KeyMap[ImGuiKey_RightArrow] = 262;
    io.KeyMap[ImGuiKey_Escape] = 256;
    unsigned char* pixels = nullptr;
    int w = 0, h = 0;
    io.Fonts->GetTexDataAsRGBA32(&pixels, &w, &h);  // a font atlas, no texture upload
  }
  ~ImGuiHeadless() { ImGui::DestroyContext(); }
  // One frame of a single panel in a window of `size`.
  static void DrawPanel(UiContext& ui, Panel& panel, ImVec2 size) {
    ImGui::NewFrame();
    ImGui::SetNextWindowSize(size);
    panel.Draw(ui);
    ImGui::Render();
  }
  // One frame of the whole app; with `input`, the mouse and keys as the GL app gives them
  // (CopyToImGui) for that frame.
  void Frame(UiContext& ui, std::vector<std::unique_ptr<Panel>>& panels,
             const InputState* input = nullptr) {
    if (input) CopyToImGui(*input, &ImGui::GetIO());
    ApplyUiScale(ui.scale.Total(), &ui.scale_applied);  // as the GL app does between frames
    ImGui::NewFrame();
    DrawAppFrame(ui, panels);
    ImGui::Render();
  }
};

// The whole app headless over a real painting worker on `project`, paused at `frame`, in a
// display of `display` pixels; each frame's mouse and keys come from `input`.
struct HeadlessApp {
  HeadlessApp(const std::string& project, int frame, ImVec2 display = ImVec2(1600, 1000)) {
    EXPECT_TRUE(state.Open(project).ok()) << project;
    runner.Restart(state.project);
    runner.Seek(frame);
    runner.WaitIdle();
    ui.state = &state;
    ui.runner = &runner;
    ui.calibration = &calibration;
    ui.textures = &textures;
    ui.viewport = &viewport;
    panels = MakePanels();
    ImGui::GetIO().DisplaySize = display;
    Frames(4);  // scroll bars and content sizes settle over a few frames
  }
  void Frame() {
    ui.snapshot = runner.Snapshot();
    imgui.Frame(ui, panels, &input);
  }
  void Frames(int n) {
    for (int i = 0; i < n; ++i) Frame();
  }
  // Frames until the queued events are all in, and one more.
  void Drain(InputQueue* queue) {
    while (queue->pending() > 0) {
      queue->NextFrame(&input);
      Frame();
    }
    queue->NextFrame(&input);
    Frame();
  }
  void MouseTo(float x, float y) { input.mouse_x = x, input.mouse_y = y; }
  // Presses the left button at `from`, moves to `to` in `steps` frames, releases.
  void Drag(ImVec2 from, ImVec2 to, int steps) {
    MouseTo(from.x, from.y);
    Frames(2);
    input.mouse_down[0] = true;
    Frame();
    for (int s = 1; s <= steps; ++s) {
      MouseTo(from.x + (to.x - from.x) * s / steps, from.y + (to.y - from.y) * s / steps);
      Frame();
    }
    input.mouse_down[0] = false;
    Frame();
  }
  // Ctrl+`key` pressed and released between two frames (queued as the window's callbacks
  // queue them), then the frames that take the events in.
  void CtrlTap(int key) {
    InputQueue queue;
    for (auto [code, down] :
         {std::pair{kKeyLeftControl, true}, {key, true}, {key, false}, {kKeyLeftControl, false}}) {
      InputEvent e;
      e.kind = InputEvent::Kind::kKey;
      e.code = code;
      e.down = down;
      queue.Push(e);
    }
    Drain(&queue);
  }
  // Presses and releases mouse `button` (0 left, 1 right) at `at`.
  void Click(ImVec2 at, int button = 0) {
    MouseTo(at.x, at.y);
    Frame();
    input.mouse_down[button] = true;
    Frame();
    input.mouse_down[button] = false;
    Frame();
  }
  Panel& Find(const std::string& title) {
    for (auto& p : panels)
      if (title == p->Title()) return *p;
    ADD_FAILURE() << "no panel " << title;
    return *panels.front();
  }
  std::string ReportOf(const std::string& title, const std::string& key) {
    const auto report = Find(title).Report();
    const auto it = report.find(key);
    return it == report.end() ? "" : it->second;
  }
  // A panel's window by its title, or another window by its name ("##Menu_00").
  static ImGuiWindow* Window(const std::string& title) {
    ImGuiWindow* w = ImGui::FindWindowByName(PanelWindowId(title).c_str());
    if (!w) w = ImGui::FindWindowByName(title.c_str());
    EXPECT_NE(w, nullptr) << title;
    return w;
  }

  AppState state;
  PipelineRunner runner;
  NullTextures textures;
  NullViewport viewport;
  CalibrationRunner calibration;
  UiContext ui;
  ImGuiHeadless imgui;
  std::vector<std::unique_ptr<Panel>> panels;
  InputState input;
};

// Keyboard navigation's activation of item `id` of `window` (a button presses, an input
// takes the keys), as the next frame sees it.
inline void Activate(HeadlessApp& app, const std::string& window, const char* id) {
  ImGui::ActivateItem(HeadlessApp::Window(window)->GetID(id));
  app.Frame();
}

// Types `text` into input `id` of `window`, then leaves it.
inline void TypeInto(HeadlessApp& app, const std::string& window, const char* id,
                     const std::string& text) {
  ImGui::ActivateItem(HeadlessApp::Window(window)->GetID(id));
  GImGui->NavNextActivateFlags = ImGuiActivateFlags_PreferInput;  // as the keyboard does
  app.Frame();
  EXPECT_EQ(ImGui::GetActiveID(), HeadlessApp::Window(window)->GetID(id)) << id;
  ImGui::GetIO().AddInputCharactersUTF8(text.c_str());
  app.Frame();
  ImGui::ClearActiveID();
  app.Frame();
}

// Groups `a` and `b` merged (as the Grouping panel's "Merge groups" does) and painted again
// at the same frame.
inline void MergeAndApply(HeadlessApp& app, int a, int b) {
  const auto geometry = app.runner.Snapshot()->geometry;
  std::vector<GroupSpec> merged;
  ASSERT_TRUE(MergeGroups(geometry->groups, static_cast<int>(geometry->buffer_of_triangle.size()),
                          {a, b}, &merged)
                  .ok());
  app.state.BeginEdit();
  app.state.project.grouping.groups = merged;
  ApplyProject(app.ui);
  app.runner.WaitIdle();
  app.Frames(2);
}

}  // namespace fresco::testing
