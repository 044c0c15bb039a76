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

#include "tests/test_support.h"
#include "ui/core/app_frame.h"
#include "ui/core/input_queue.h"
#include "ui/core/panel.h"

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
    // The keys as ImGui's GLFW backend maps them (GLFW key codes).
    io.KeyMap[ImGuiKey_Space] = 32;
    io.KeyMap[ImGuiKey_LeftArrow] = 263;
    io.KeyMap[ImGuiKey_RightArrow] = 262;
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
    ImGui::NewFrame();
    DrawAppFrame(ui, panels);
    ImGui::Render();
  }
};

}  // namespace fresco::testing
