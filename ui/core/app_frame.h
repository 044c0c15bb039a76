// One frame of the whole app's UI: the menu bar (file, edit, view), every open panel, the
// unsaved-changes prompt and the status bar. Shared by the GL app and the headless tests.
#pragma once

#include <memory>
#include <vector>

#include "ui/core/panel.h"

namespace fresco {

void DrawAppFrame(UiContext& ui, std::vector<std::unique_ptr<Panel>>& panels);

// The app's Dear ImGui settings (the GL app and the headless tests): windows move by their
// title bar only, so a drag on an image or a plot never moves its window.
void ConfigureImGui(ImGuiIO* io);

}  // namespace fresco
