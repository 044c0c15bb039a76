#include "ui/core/app_frame.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <set>
#include <string>

#include <imgui_internal.h>

#include "ui/panels/panels.h"
#include "ui/panels/path_field.h"

namespace fresco {
namespace {

const ImVec4 kErrorColour(1.0f, 0.4f, 0.4f, 1.0f);

// ImGui 1.86 indexes io.KeysDown by the backend's key codes: GLFW_KEY_F5 (letters are
// their ASCII capitals there, as 'S' below).
constexpr int kKeyF5 = 294;
// GLFW's codes for the font-scale shortcuts: "=" (with shift "+"), "-", keypad + and -.
constexpr int kKeyEqual = 61, kKeyMinus = 45, kKeyKeypadAdd = 334, kKeyKeypadSubtract = 333;
constexpr float kSplitterPx = 5;  // the bars between tiled panels
constexpr const char* kSwapPopup = "##swap places";
constexpr float kMinTilePx = 120;        // a splitter stops before a side gets narrower
constexpr float kTabStripPaddingPx = 2;  // around the tabs of a tab group

bool IsError(const std::string& text) { return text.rfind("error: ", 0) == 0; }

void OpenNow(UiContext& ui, const std::string& path) {
  const std::string note = std::move(ui.state->pending_open_note);
  ui.state->pending_open_note.clear();
  if (Status s = ui.state->Open(path); !s.ok()) {
    ui.state->message = "error: " + s.message();
    return;
  }
  if (!note.empty()) ui.state->message += "; " + note;
  ReopenProject(ui);
}

// The worker could not read what the project names (a corrupt video or poses file): the
// worker's error replaces "opened ...", and the project leaves the recent list.
void CheckOpened(UiContext& ui) {
  const RunnerSnapshot& snap = *ui.snapshot;
  if (!ui.open_pending || snap.version <= ui.opened_version) return;
  ui.open_pending = false;
  if (!IsError(snap.status)) return;
  ui.state->RemoveRecent(ui.state->project.file_path);
  ui.state->message = snap.status;
}

void DrawUnsavedPrompt(UiContext& ui) {
  AppState& state = *ui.state;
  const bool waiting = !state.pending_open.empty() || state.pending_quit;
  if (!waiting) return;
  auto proceed = [&] {  // quit, or open the other project
    if (state.pending_quit)
      ui.request_quit = true;
    else
      OpenNow(ui, state.pending_open);
    state.pending_open.clear();
    state.pending_quit = false;
  };
  if (!state.dirty) {  // nothing to lose
    proceed();
    return;
  }
  if (!ImGui::IsPopupOpen("Unsaved changes")) ImGui::OpenPopup("Unsaved changes");
  if (ImGui::BeginPopupModal("Unsaved changes", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
    ImGui::Text("%s has unsaved changes.", state.project.file_path.c_str());
    bool go_on = false;
    if (ImGui::Button("Save")) {
      if (Status s = state.Save(); !s.ok())
        state.message = "error: " + s.message();
      else
        go_on = true;
    }
    ImGui::SameLine();
    // The edits go with the project only once another opens (AppState::Open): when it does
    // not, they are still the open project's, and still unsaved.
    if (ImGui::Button("Discard")) go_on = true;
    ImGui::SameLine();
    if (ImGui::Button("Cancel")) {
      state.pending_open.clear();
      state.pending_open_note.clear();
      state.pending_quit = false;
      ImGui::CloseCurrentPopup();
    }
    if (go_on) {
      ImGui::CloseCurrentPopup();
      proceed();
    }
    ImGui::EndPopup();
  }
}

// File > Open and Save As: a project file's path, wide enough to read one (a menu is only as
// wide as what it holds).
PathFieldOptions MenuPath(UiContext& ui) {
  return {.extensions = {".json"},
          .min_width_px = ImGui::GetFontSize() * 30,
          .last_folder = &ui.state->last_folder};
}

void DrawMenuBar(UiContext& ui, std::vector<std::unique_ptr<Panel>>& panels) {
  AppState& state = *ui.state;
  if (!ImGui::BeginMainMenuBar()) return;
  if (ImGui::BeginMenu("File")) {
    if (ImGui::MenuItem("New project...")) ui.new_project_requested = true;
    // Open and Save As take a path (typed, or picked with "..." from the folder typed so far).
    if (ImGui::BeginMenu("Open...")) {
      PathField("project", "##menu_open", "project.json to open", &ui.menu_path, MenuPath(ui));
      if (ImGui::MenuItem("Open", nullptr, false, !ui.menu_path.empty()))
        RequestOpen(ui, ui.menu_path);
      ImGui::EndMenu();
    }
    if (ImGui::MenuItem("Save", "Ctrl+S", false, state.has_project))
      if (Status s = state.Save(); !s.ok()) state.message = "error: " + s.message();
    if (ImGui::BeginMenu("Save As...", state.has_project)) {
      PathField("as", "##menu_save_as", "path for Save As", &ui.menu_path, MenuPath(ui));
      if (ImGui::MenuItem("Save As", nullptr, false, !ui.menu_path.empty()))
        if (Status s = state.Save(ui.menu_path); !s.ok()) state.message = "error: " + s.message();
      ImGui::EndMenu();
    }
    if (ImGui::BeginMenu("Open recent", !state.recent.empty())) {
      for (const std::string& path : state.recent)
        if (ImGui::MenuItem(path.c_str())) RequestOpen(ui, path);
      ImGui::EndMenu();
    }
    if (ImGui::MenuItem("Quit", "Ctrl+Q")) state.pending_quit = true;
    ImGui::EndMenu();
  }
  if (ImGui::BeginMenu("Edit")) {
    if (ImGui::MenuItem("Undo", "Ctrl+Z", false, !state.undo.empty())) UndoRedo(ui, true);
    if (ImGui::MenuItem("Redo", "Ctrl+Y", false, !state.redo.empty())) UndoRedo(ui, false);
    if (ImGui::MenuItem("Apply (repaint up to this frame)", "F5", false, state.has_project))
      ApplyProject(ui);
    ImGui::EndMenu();
  }
  if (ImGui::BeginMenu("View")) {
    for (auto& panel : panels) ImGui::MenuItem(panel->Title(), nullptr, &panel->open);
    ImGui::Separator();
    TileLayout& layout = ui.layout;
    if (ImGui::BeginMenu("Maximise")) {  // also: double-click a panel's title bar
      for (auto& panel : panels)
        if (layout.Contains(panel->Title()) &&
            ImGui::MenuItem(panel->Title(), nullptr, layout.maximised() == panel->Title(),
                            panel->open))
          layout.ToggleMaximised(panel->Title());
      ImGui::EndMenu();
    }
    if (ImGui::MenuItem("Restore", nullptr, false, !layout.maximised().empty()))
      layout.ToggleMaximised(layout.maximised());
    if (ImGui::MenuItem("Default layout")) layout = DefaultTileLayout();
    // No control here, where a stray click would change it: the status bar's A- and A+.
    ImGui::Separator();
    ImGui::TextDisabled("font scale %.2f: A- A+ in the status bar, Ctrl+- Ctrl+=", ui.scale.user);
    ImGui::EndMenu();
  }
  const auto& snap = *ui.snapshot;
  ImGui::Separator();
  if (IsError(snap.status)) {  // said once, in the status bar
    ImGui::TextColored(kErrorColour, "error (see the status bar)");
  } else {
    ImGui::Text("%s  %s  coverage %.1f%%  %s", FrameLabel(snap).c_str(), StatusText(snap).c_str(),
                100.0 * snap.coverage, state.dirty ? "[unsaved]" : "");
  }
  ImGui::EndMainMenuBar();
}

// Escape closes the menu, "..." list or popup on top, one at a time (ImGui 1.86 does so only
// with keyboard navigation, which the app leaves off); a modal prompt answers it itself, and
// a field being typed in takes it first (it leaves the field). What a list put in its field
// stays there.
void CloseTopPopupOnEscape() {
  ImGuiContext& g = *GImGui;
  if (g.OpenPopupStack.empty() || !ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape), false))
    return;
  const ImGuiWindow* top = g.OpenPopupStack.back().Window;
  if (top && !(top->Flags & ImGuiWindowFlags_Modal))
    ImGui::ClosePopupToLevel(g.OpenPopupStack.Size - 1, true);
}

void HandleShortcuts(UiContext& ui) {
  ImGuiIO& io = ImGui::GetIO();
  if (io.WantTextInput) return;
  CloseTopPopupOnEscape();
  AppState& state = *ui.state;
  if (io.KeyCtrl && ImGui::IsKeyPressed('S') && state.has_project)
    if (Status s = state.Save(); !s.ok()) state.message = "error: " + s.message();
  if (io.KeyCtrl && ImGui::IsKeyPressed('Z')) UndoRedo(ui, true);
  if (io.KeyCtrl && ImGui::IsKeyPressed('Y')) UndoRedo(ui, false);
  if (ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Space))) {
    if (ui.snapshot->playing)
      ui.runner->Pause();
    else
      ui.runner->Play();
  }
  if (io.KeyCtrl && ImGui::IsKeyPressed('Q')) state.pending_quit = true;
  // The font scale, a step at a time (applied from the next frame on: ApplyUiScale).
  if (io.KeyCtrl && (ImGui::IsKeyPressed(kKeyEqual) || ImGui::IsKeyPressed(kKeyKeypadAdd)))
    ui.scale.user = StepFontScale(ui.scale.user, +1);
  if (io.KeyCtrl && (ImGui::IsKeyPressed(kKeyMinus) || ImGui::IsKeyPressed(kKeyKeypadSubtract)))
    ui.scale.user = StepFontScale(ui.scale.user, -1);
  if (io.KeyCtrl && ImGui::IsKeyPressed('0')) ui.scale.user = 1;
  if (ImGui::IsKeyPressed(kKeyF5, false) && state.has_project) ApplyProject(ui);
  // Left: back one frame (a file source repaints from the start); Right: the next frame.
  const RunnerSnapshot& snap = *ui.snapshot;
  if (ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_LeftArrow), false) && !snap.live.active &&
      ShownFrame(snap) > 0)
    ui.runner->Seek(ShownFrame(snap) - 1);
  if (ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_RightArrow), false) && state.has_project)
    ui.runner->Step();
}

// The font scale at the status bar's right end: A- and A+ step it (kFontScaleSteps). Drawn
// first, the message then starts at the left.
// Returns where the steps start (screen x): the status message is cut short of them.
float DrawFontScaleSteps(UiContext& ui) {
  const ImGuiStyle& style = ImGui::GetStyle();
  const std::string label = std::to_string(static_cast<int>(ui.scale.user * 100 + 0.5f)) + " %";
  const float width = ImGui::CalcTextSize("A-").x + ImGui::CalcTextSize("A+").x +
                      ImGui::CalcTextSize(label.c_str()).x + 4 * style.FramePadding.x +
                      2 * style.ItemSpacing.x;
  const ImVec2 start = ImGui::GetCursorPos();
  const float left = ImGui::GetWindowContentRegionMax().x - width;
  ImGui::SetCursorPosX(left);
  const float smallest = kFontScaleSteps[0];
  const float largest = kFontScaleSteps[std::size(kFontScaleSteps) - 1];
  ImGui::BeginDisabled(ui.scale.user <= smallest);
  if (ImGui::SmallButton("A-")) ui.scale.user = StepFontScale(ui.scale.user, -1);
  ImGui::EndDisabled();
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip("smaller text (Ctrl+-; Ctrl+0: 100 %%)");
  ImGui::SameLine();
  ImGui::TextUnformatted(label.c_str());
  ImGui::SameLine();
  ImGui::BeginDisabled(ui.scale.user >= largest);
  if (ImGui::SmallButton("A+")) ui.scale.user = StepFontScale(ui.scale.user, +1);
  ImGui::EndDisabled();
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip("larger text (Ctrl+=; Ctrl+0: 100 %%)");
  ImGui::SetCursorPos(start);
  return ImGui::GetWindowPos().x + left;
}

void DrawStatusBar(UiContext& ui) {
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  ImGui::SetNextWindowPos(ImVec2(0, display.y - StatusBarHeight()));
  ImGui::SetNextWindowSize(ImVec2(display.x, StatusBarHeight()));
  ImGui::Begin("##status", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoScrollWithMouse |
                   ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoBringToFrontOnFocus);
  const float steps_x = DrawFontScaleSteps(ui);
  // The messages stop short of the font-scale steps (a long one is cut, not drawn over them).
  const ImVec2 pos = ImGui::GetWindowPos();
  ImGui::PushClipRect(
      pos, ImVec2(steps_x - ImGui::GetStyle().ItemSpacing.x, pos.y + ImGui::GetWindowSize().y),
      true);
  // One message: the worker's error replaces "opened ..." (the project named a file it
  // could not read); other messages (saved, grouping edited) stay beside it.
  const std::string& message = ui.state->message;
  if (IsError(ui.snapshot->status)) {
    ImGui::TextColored(kErrorColour, "%s", ui.snapshot->status.c_str());
    if (!message.empty() && message.rfind("opened ", 0) != 0 && message != ui.snapshot->status) {
      ImGui::SameLine();
      ImGui::TextUnformatted(("  " + message).c_str());
    }
  } else if (IsError(message)) {
    ImGui::TextColored(kErrorColour, "%s", message.c_str());
  } else {
    ImGui::TextUnformatted(message.c_str());
  }
  if (const std::string& problem = ui.snapshot->live.problem; !problem.empty()) {
    ImGui::SameLine();  // a live source that stalled, dropped or ended
    ImGui::TextColored(kErrorColour, "  live: %s", problem.c_str());
  }
  ImGui::PopClipRect();
  ImGui::End();
}

bool OpenOrBusy(const Panel& panel) { return panel.open || panel.Busy(); }

// A panel opened since the last frame (View menu, File > New project..., the command line)
// comes to the front of its tab group.
void ShowOpenedTabs(UiContext& ui, const std::vector<std::unique_ptr<Panel>>& panels) {
  std::set<std::string> open;
  for (const auto& panel : panels) {  // in menu order: tools opened with the app come last
    if (!OpenOrBusy(*panel)) continue;
    open.insert(panel->Title());
    if (!ui.open_last_frame.count(panel->Title())) ui.layout.ShowTab(panel->Title());
  }
  ui.open_last_frame = std::move(open);
}

// The tiled panels' places this frame (between the menu bar and the status bar); returns the
// splitters and the tab groups' strips.
std::vector<TileLayout::Splitter> PlaceTiles(const TileLayout& layout,
                                             std::vector<std::unique_ptr<Panel>>& panels,
                                             std::vector<TileLayout::TabStrip>* strips) {
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  const float top = std::ceil(ImGui::GetFrameHeight());  // the menu bar's height
  const LayoutRect band{0, top, display.x, std::max(0.0f, display.y - top - StatusBarHeight())};
  auto is_open = [&](const std::string& title) {
    for (const auto& p : panels)
      if (title == p->Title()) return OpenOrBusy(*p);
    return false;
  };
  std::vector<TileLayout::Tile> tiles;
  std::vector<TileLayout::Splitter> splitters;
  layout.Compute(band, kSplitterPx, is_open, &tiles, &splitters, strips,
                 std::round(ImGui::GetFrameHeight() + 2 * kTabStripPaddingPx));
  for (auto& panel : panels) {
    panel->tiled = false;
    for (const TileLayout::Tile& t : tiles) {
      if (t.panel != panel->Title()) continue;
      panel->tiled = true;
      panel->tile_pos = ImVec2(t.rect.x, t.rect.y);
      panel->tile_size = ImVec2(t.rect.w, t.rect.h);
    }
  }
  return splitters;
}

// The strips of tab groups with two or more sides open: a click on a tab brings its side to
// the front; the others stay open behind their tabs.
void DrawTabStrips(UiContext& ui, const std::vector<TileLayout::TabStrip>& strips) {
  ui.tabs_drawn.clear();
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(kTabStripPaddingPx, kTabStripPaddingPx));
  ImGui::PushStyleVar(ImGuiStyleVar_WindowMinSize, ImVec2(1, 1));
  for (const TileLayout::TabStrip& strip : strips) {
    ImGui::SetNextWindowPos(ImVec2(strip.rect.x, strip.rect.y));
    ImGui::SetNextWindowSize(ImVec2(strip.rect.w, strip.rect.h));
    ImGui::Begin(("##tabs" + std::to_string(strip.node)).c_str(), nullptr,
                 ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoSavedSettings |
                     ImGuiWindowFlags_NoBringToFrontOnFocus | ImGuiWindowFlags_NoScrollWithMouse);
    for (size_t k = 0; k < strip.names.size(); ++k) {
      const bool shown = static_cast<int>(k) == strip.shown;
      if (k > 0) ImGui::SameLine(0, 2);
      ImGui::PushStyleColor(ImGuiCol_Button,
                            ImGui::GetStyleColorVec4(shown ? ImGuiCol_TabActive : ImGuiCol_Tab));
      ImGui::PushStyleColor(ImGuiCol_ButtonHovered, ImGui::GetStyleColorVec4(ImGuiCol_TabHovered));
      if (ImGui::Button(strip.names[k].c_str())) ui.layout.ShowTabNamed(strip.node, strip.names[k]);
      ImGui::PopStyleColor(2);
      const ImVec2 lo = ImGui::GetItemRectMin(), hi = ImGui::GetItemRectMax();
      ui.tabs_drawn[strip.names[k]] = {lo.x, lo.y, hi.x - lo.x, hi.y - lo.y};
    }
    ImGui::End();
  }
  ImGui::PopStyleVar(2);
}

// The bars between tiles: drag to resize the panels on both sides.
void DrawSplitters(TileLayout* layout, const std::vector<TileLayout::Splitter>& splitters) {
  ImGui::PushStyleVar(ImGuiStyleVar_WindowMinSize, ImVec2(1, 1));
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(0, 0));
  ImGui::PushStyleVar(ImGuiStyleVar_WindowBorderSize, 0.0f);
  for (const TileLayout::Splitter& s : splitters) {
    const std::string name = "##splitter" + std::to_string(s.node);
    ImGui::SetNextWindowPos(ImVec2(s.rect.x, s.rect.y));
    ImGui::SetNextWindowSize(ImVec2(s.rect.w, s.rect.h));
    ImGui::Begin(name.c_str(), nullptr,
                 ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoSavedSettings |
                     ImGuiWindowFlags_NoBackground | ImGuiWindowFlags_NoBringToFrontOnFocus |
                     ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoScrollWithMouse);
    ImGui::InvisibleButton("##bar", ImVec2(std::max(1.0f, s.rect.w), std::max(1.0f, s.rect.h)));
    const ImGuiIO& io = ImGui::GetIO();
    if (ImGui::IsItemActive())
      layout->Drag(s, s.stacked ? io.MouseDelta.y : io.MouseDelta.x, kMinTilePx);
    if (ImGui::IsItemHovered() || ImGui::IsItemActive()) {
      ImGui::SetMouseCursor(s.stacked ? ImGuiMouseCursor_ResizeNS : ImGuiMouseCursor_ResizeEW);
      ImGui::GetWindowDrawList()->AddRectFilled(ImVec2(s.rect.x, s.rect.y),
                                                ImVec2(s.rect.x + s.rect.w, s.rect.y + s.rect.h),
                                                ImGui::GetColorU32(ImGuiCol_SeparatorActive));
    }
    ImGui::End();
  }
  ImGui::PopStyleVar(3);
}

}  // namespace

void RequestOpen(UiContext& ui, const std::string& path) { ui.state->pending_open = path; }

void ReopenProject(UiContext& ui) {
  ui.runner->Restart(ui.state->project);
  ui.open_pending = true;
  ui.opened_version = ui.snapshot ? ui.snapshot->version : 0;
}

void UndoRedo(UiContext& ui, bool undo) {
  const GroupingOptions before = ui.state->project.grouping;
  const double texel_before = ui.state->project.pipeline.texel_size_m;
  const ProjectPaths paths_before = EditablePaths(ui.state->project);
  if (!(undo ? ui.state->Undo() : ui.state->Redo())) return;
  // A grouping, poses (Poses panel) or path (Project panel) change shows only once the
  // session is rebuilt.
  if (!(before == ui.state->project.grouping) ||
      texel_before != ui.state->project.pipeline.texel_size_m ||
      !(paths_before == EditablePaths(ui.state->project)))
    ApplyProject(ui);
}

void ApplyProject(UiContext& ui) {
  if (!ui.state->has_project) return;
  // Back to the frame being looked at (or sought), where the source can go back to it.
  const RunnerSnapshot* snap = ui.snapshot.get();
  const int frame = !snap || snap->live.active ? -1
                    : snap->seek_target >= 0   ? snap->seek_target
                                               : snap->frame;
  ui.runner->Restart(ui.state->project);
  if (frame >= 0) ui.runner->Seek(frame);
}

// The menu a right-click on a tiled panel's title opens: the other tiled panels, to swap
// places with (the layout file keeps the places).
void DrawSwapMenu(UiContext& ui, const std::vector<std::unique_ptr<Panel>>& panels) {
  if (!ImGui::BeginPopup(kSwapPopup)) return;
  ImGui::TextDisabled("Swap places of %s with", ui.swapping.c_str());
  ImGui::Separator();
  for (const auto& panel : panels) {
    const std::string title = panel->Title();
    if (title == ui.swapping || !ui.layout.Contains(title)) continue;
    if (ImGui::MenuItem(title.c_str(), nullptr, false, panel->open)) {
      ui.layout.Swap(ui.swapping, title);
      ui.state->message = ui.swapping + " and " + title + " swapped places";
    }
  }
  ImGui::EndPopup();
}

void ConfigureImGui(ImGuiIO* io) { io->ConfigWindowsMoveFromTitleBarOnly = true; }

void DrawAppFrame(UiContext& ui, std::vector<std::unique_ptr<Panel>>& panels) {
  CheckOpened(ui);
  PlaceDroppedPaths(ui, panels);
  HandleShortcuts(ui);
  LetAClickOutsideABrowseListThrough();
  DrawMenuBar(ui, panels);
  if (ui.new_project_requested) {
    for (auto& panel : panels)
      if (std::string(panel->Title()) == kNewProjectTitle) panel->open = true;
    ui.new_project_requested = false;
  }
  ShowOpenedTabs(ui, panels);
  std::vector<TileLayout::TabStrip> strips;
  const std::vector<TileLayout::Splitter> splitters = PlaceTiles(ui.layout, panels, &strips);
  DrawTabStrips(ui, strips);
  for (auto& panel : panels) {
    // A tiled panel without a tile is hidden behind a maximised one or behind another tab.
    if (OpenOrBusy(*panel) && (panel->tiled || !ui.layout.Contains(panel->Title())))
      panel->Draw(ui);
    if (panel->maximise_requested) ui.layout.ToggleMaximised(panel->Title());
    panel->maximise_requested = false;
    if (panel->swap_menu_requested) {
      ui.swapping = panel->Title();
      ImGui::OpenPopup(kSwapPopup);
    }
    panel->swap_menu_requested = false;
  }
  DrawSwapMenu(ui, panels);
  DrawSplitters(&ui.layout, splitters);
  DrawUnsavedPrompt(ui);
  DrawStatusBar(ui);
}

}  // namespace fresco
