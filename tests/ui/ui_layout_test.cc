// The app's tiled layout driven headless: the 3D view is the largest panel by default, at
// 1600 x 1000 and at 1280 x 800 every tile is wide enough; a splitter drag resizes both
// neighbours; a double-click on a title bar maximises a panel and another restores the
// layout; closing a panel gives its space to its neighbour; the font scale applies; on a 4K
// monitor at twice the density the layout and text are twice the size.
#include <algorithm>
#include <chrono>
#include <fstream>

#include <gtest/gtest.h>
#include <imgui.h>
#include <imgui_internal.h>

#include "tests/ui/headless_ui.h"
#include "ui/core/calibration_runner.h"
#include "ui/core/poses_runner.h"
#include "ui/core/tile_layout.h"
#include "ui/panels/panels.h"
#include "ui/panels/path_field.h"

namespace fresco {
namespace {

using testing::Capture;

struct LayoutApp : testing::HeadlessApp {
  explicit LayoutApp(ImVec2 display) : HeadlessApp(Capture() + "/project.json", 2, display) {}
  static bool Shown(const char* title) {
    ImGuiWindow* w = ImGui::FindWindowByName(PanelWindowId(title).c_str());
    return w && w->Active;
  }
};

TEST(UiLayout, EveryTiledPanelExistsAndTheLayoutCoversTheBand) {
  const TileLayout layout = DefaultTileLayout();
  auto panels = MakePanels();
  int tiled = 0;
  for (const auto& p : panels) tiled += layout.Contains(p->Title());
  EXPECT_EQ(tiled, static_cast<int>(panels.size())) << "every panel, the tools too";
  std::vector<TileLayout::Tile> tiles;
  std::vector<TileLayout::Splitter> splitters;
  std::vector<TileLayout::TabStrip> strips;
  layout.Compute(
      {0, 20, 1600, 956}, 5, [](const std::string&) { return true; }, &tiles, &splitters, &strips,
      24);
  // All open: Calibration, Poses and New project wait behind the stage row's tab.
  EXPECT_EQ(tiles.size(), static_cast<size_t>(tiled) - 3);
  EXPECT_EQ(splitters.size(), tiles.size() - 1);
  ASSERT_EQ(strips.size(), 1u);
  EXPECT_EQ(strips[0].names,
            (std::vector<std::string>{"Stages", "Poses", "Calibration", "New project"}));
  double area = strips[0].rect.w * strips[0].rect.h;
  for (const auto& t : tiles) area += t.rect.w * t.rect.h;
  for (const auto& s : splitters) area += s.rect.w * s.rect.h;
  EXPECT_NEAR(area, 1600.0 * 956, 1600.0 * 956 * 0.005) << "tiles, bars and tabs fill the band";
}

void ExpectUsable(ImVec2 display, float content_scale = 1) {
  LayoutApp app(display);
  app.ui.scale.content = content_scale;  // the monitor's, as GLFW reports it
  app.Frames(4);
  const float s = content_scale;
  float view_area = 0, largest_other = 0;
  for (const auto& p : app.panels) {
    if (!p->open) continue;
    ImGuiWindow* w = LayoutApp::Window(p->Title());
    ASSERT_NE(w, nullptr) << p->Title();
    EXPECT_GE(w->Size.x, 150 * s) << p->Title() << " at " << display.x << "x" << display.y;
    EXPECT_GE(w->Size.y, 120 * s) << p->Title() << " at " << display.x << "x" << display.y;
    EXPECT_GE(w->Pos.y, ImGui::GetFrameHeight()) << p->Title();
    EXPECT_LE(w->Pos.x + w->Size.x, display.x + 0.5f) << p->Title();
    EXPECT_LE(w->Pos.y + w->Size.y, display.y - StatusBarHeight() + 0.5f) << p->Title();
    const float area = w->Size.x * w->Size.y;
    if (std::string(p->Title()) == "3D view")
      view_area = area;
    else
      largest_other = std::max(largest_other, area);
  }
  EXPECT_GT(view_area, 1.5f * largest_other) << "the 3D view is the large one";
  EXPECT_GT(view_area, 0.15f * display.x * display.y);
  // Nothing is clipped at the right edge (ImGui would need to scroll sideways).
  for (const auto& p : app.panels) {
    if (p->open) {
      EXPECT_EQ(LayoutApp::Window(p->Title())->ScrollMax.x, 0) << p->Title();
    }
  }
}

TEST(UiLayout, The3DViewIsLargeAndEveryTileUsableAt1600x1000) { ExpectUsable({1600, 1000}); }
TEST(UiLayout, The3DViewIsLargeAndEveryTileUsableAt1280x800) { ExpectUsable({1280, 800}); }
// At 1280 x 800 every title bar shows its panel's title whole or shortened, never cut in the
// middle of a word ("Stage: depth and vi"), the tool panels' tabs too; and a panel's window
// stays the same ImGui window whatever its title bar shows.
TEST(UiLayout, EveryTitleFitsItsTitleBarAt1280x800) {
  LayoutApp app({1280, 800});
  for (const char* tool : {kPosesPanelTitle, kCalibrationPanelTitle, kNewProjectTitle})
    app.Find(tool).open = true;
  app.Frames(3);
  const ImGuiStyle& style = ImGui::GetStyle();
  for (const auto& p : app.panels) {
    if (!p->open || !LayoutApp::Shown(p->Title())) continue;
    ImGuiWindow* w = LayoutApp::Window(p->Title());
    const std::string name = w->Name;
    const std::string shown = name.substr(0, name.find("###"));
    EXPECT_EQ(name.substr(shown.size()), PanelWindowId(p->Title())) << name;
    const float room = w->Size.x - 2 * style.FramePadding.x - ImGui::GetFontSize();
    EXPECT_LE(ImGui::CalcTextSize(shown.c_str()).x, room)
        << p->Title() << " shows '" << shown << "'";
    EXPECT_TRUE(shown == p->Title() || shown == p->ShortTitle())
        << p->Title() << " shows '" << shown << "'";
  }
  EXPECT_EQ(std::string(LayoutApp::Window("Stage: depth and visibility")->Name),
            "Depth###Stage: depth and visibility");
}

// A 4K monitor at 192 dpi (content scale 2): the same layout at twice the size, the text
// drawn from a font built at 26 pixels (crisp, not a 13-pixel font magnified), the status bar
// as tall as its text needs.
TEST(UiLayout, The3DViewIsLargeAndEveryTileUsableAt3840x2160OnADenseMonitor) {
  ExpectUsable({3840, 2160}, 2);
  LayoutApp app({3840, 2160});
  const float frame_height = ImGui::GetFrameHeight();
  app.ui.scale.content = 2;
  app.Frames(2);
  EXPECT_EQ(ImGui::GetIO().FontGlobalScale, 1.0f);
  EXPECT_EQ(ImGui::GetIO().Fonts->Fonts[0]->FontSize, 26.0f);
  EXPECT_NEAR(ImGui::GetFrameHeight(), 2 * frame_height, 1.0f);
  EXPECT_GE(StatusBarHeight(), ImGui::GetFrameHeight() + 4);
  EXPECT_GE(LayoutApp::Window("Project")->Pos.y, ImGui::GetFrameHeight());
}

TEST(UiLayout, DraggingASplitterResizesBothNeighbours) {
  LayoutApp app({1600, 1000});
  ImGuiWindow* view = LayoutApp::Window("3D view");
  ImGuiWindow* input = LayoutApp::Window("Input frame");
  const float view_w = view->Size.x, input_w = input->Size.x;
  const float bar_x = 0.5f * (view->Pos.x + view->Size.x + input->Pos.x);
  const float y = view->Pos.y + 0.5f * view->Size.y;
  app.input.mouse_x = bar_x, app.input.mouse_y = y;
  app.Frames(2);
  app.input.mouse_down[0] = true;
  app.Frames(1);
  for (int s = 1; s <= 5; ++s) {
    app.input.mouse_x = bar_x + 20 * s;
    app.Frames(1);
  }
  app.input.mouse_down[0] = false;
  app.Frames(2);
  EXPECT_NEAR(view->Size.x, view_w + 100, 1.5f);
  EXPECT_NEAR(input->Size.x, input_w - 100, 1.5f);
  EXPECT_NEAR(input->Pos.x, view->Pos.x + view->Size.x + 5, 1.5f);
  // A splitter stops before a side gets too narrow.
  app.input.mouse_x = view->Pos.x + view->Size.x + 2.5f;
  app.Frames(1);
  app.input.mouse_down[0] = true;
  app.Frames(1);
  app.input.mouse_x += 2000;
  app.Frames(1);
  app.input.mouse_down[0] = false;
  app.Frames(2);
  EXPECT_GE(input->Size.x, 115);
}

TEST(UiLayout, DoubleClickOnATitleBarMaximisesAndRestores) {
  LayoutApp app({1600, 1000});
  ImGuiWindow* warp = LayoutApp::Window("Stage: warp to buffer");
  const ImVec2 pos = warp->Pos, size = warp->Size;
  const ImVec2 title(pos.x + 30, pos.y + 4);
  app.Click(title);
  app.Click(title);  // the second click within the double-click time
  app.Frames(1);
  EXPECT_EQ(app.ui.layout.maximised(), "Stage: warp to buffer");
  EXPECT_EQ(warp->Pos.x, 0);
  EXPECT_EQ(warp->Size.x, 1600);
  EXPECT_FALSE(LayoutApp::Shown("3D view")) << "hidden behind the maximised panel";
  EXPECT_FALSE(LayoutApp::Shown("Pipeline"));
  app.Click(ImVec2(30, warp->Pos.y + 4));
  app.Click(ImVec2(30, warp->Pos.y + 4));
  app.Frames(1);
  EXPECT_EQ(app.ui.layout.maximised(), "");
  EXPECT_EQ(warp->Pos.x, pos.x);
  EXPECT_EQ(warp->Size.x, size.x);
  EXPECT_EQ(warp->Size.y, size.y);
  EXPECT_TRUE(LayoutApp::Shown("3D view"));
}

// A right-click on a title bar offers the other tiled panels; choosing one swaps the two
// panels' tiles (here the 3D view goes where the timing was, and back).
TEST(UiLayout, ARightClickOnATitleBarSwapsPlacesWithAnotherPanel) {
  LayoutApp app({1600, 1000});
  ImGuiWindow* view = LayoutApp::Window("3D view");
  ImGuiWindow* timing = LayoutApp::Window("Timing");
  const ImVec2 view_pos = view->Pos, view_size = view->Size, timing_pos = timing->Pos;
  app.Click(ImVec2(view_pos.x + 30, view_pos.y + 4), 1);
  const ImGuiID item = [&] {
    ImGuiWindow* popup = nullptr;
    for (ImGuiWindow* w : ImGui::GetCurrentContext()->Windows)
      if ((w->Flags & ImGuiWindowFlags_Popup) && w->Active) popup = w;
    EXPECT_TRUE(popup) << "no menu after a right-click on the title";
    return popup ? popup->GetID("Timing") : 0;
  }();
  ASSERT_NE(item, 0u);
  ImGui::ActivateItem(item);
  app.Frames(3);
  EXPECT_EQ(view->Pos.x, timing_pos.x);
  EXPECT_EQ(view->Pos.y, timing_pos.y);
  EXPECT_EQ(timing->Pos.x, view_pos.x);
  EXPECT_EQ(timing->Size.x, view_size.x);
  EXPECT_EQ(app.state.message, "3D view and Timing swapped places");
  ASSERT_TRUE(app.ui.layout.Swap("3D view", "Timing"));
  app.Frames(2);
  EXPECT_EQ(view->Pos.x, view_pos.x);
  EXPECT_EQ(view->Size.y, view_size.y);
  EXPECT_FALSE(app.ui.layout.Swap("3D view", "no such panel"));
}

TEST(UiLayout, AClosedPanelGivesItsSpaceToItsNeighbour) {
  LayoutApp app({1600, 1000});
  ImGuiWindow* view = LayoutApp::Window("3D view");
  const float view_w = view->Size.x;
  for (auto& p : app.panels)
    if (std::string(p->Title()) == "Input frame" || std::string(p->Title()) == "Painted buffers")
      p->open = false;
  app.Frames(2);
  EXPECT_GT(view->Size.x, view_w * 1.4f);
}

TEST(UiLayout, FontScaleScalesTheText) {
  LayoutApp app({1280, 800});
  const float height = ImGui::GetFrameHeight(), font = ImGui::GetFontSize();
  app.ui.scale.user = 1.5f;  // View > font scale
  app.Frames(2);
  EXPECT_NEAR(ImGui::GetFontSize(), 1.5f * font, 0.5f);
  EXPECT_NEAR(ImGui::GetFrameHeight(), 1.5f * height, 1.0f);  // paddings scaled too
  EXPECT_GE(LayoutApp::Window("Project")->Pos.y, ImGui::GetFrameHeight())
      << "tiles start below the taller menu bar";
}

// A narrow panel (issue 58, item 8): its captions do not stand one letter per line; they
// wrap at eight font sizes at least and run past a narrower edge.
struct CaptionPanel : Panel {
  const char* Title() const override { return "Caption"; }
  void Draw(UiContext&) override {
    if (BeginPanel(*this)) {
      ImGui::TextWrapped("automatic: 6 groups for 12 triangles");
      caption_height = ImGui::GetItemRectSize().y;
    }
    ImGui::End();
  }
  float caption_height = 0;
};

TEST(UiLayout, ANarrowPanelKeepsItsCaptionsOnAFewLines) {
  LayoutApp app({1280, 800});
  CaptionPanel panel;  // a tile of the layout, 60 pixels wide, then 600
  panel.tiled = true;
  panel.tile_pos = ImVec2(0, 40);
  const auto caption_lines = [&](float width) {
    panel.tile_size = ImVec2(width, 300);
    for (int i = 0; i < 2; ++i) testing::ImGuiHeadless::DrawPanel(app.ui, panel, {width, 300});
    return panel.caption_height / ImGui::GetTextLineHeight();
  };
  EXPECT_LE(caption_lines(60), 4) << "a 60-pixel tile stacks its caption letter by letter";
  EXPECT_LT(caption_lines(600), 1.5f) << "one line where it fits";
}

// The Painted buffers panel at 1280 x 800 and a larger font: the buffer's caption goes below
// its slider where it does not fit beside it, instead of wrapping a few letters a line in
// the room left beside the slider.
TEST(UiLayout, ThePaintedBufferCaptionStaysOnALineAtALargerFont) {
  LayoutApp app({1280, 800});
  for (const float scale : {1.0f, 1.5f, 2.0f}) {
    app.ui.scale.user = scale;
    app.Frames(4);
    const float lines = std::stof(app.ReportOf("Painted buffers", "caption lines"));
    EXPECT_GE(lines, 0.9f) << "no caption at font scale " << scale;
    // On a line of its own it may wrap once, at a space (the panel is narrower than it).
    EXPECT_LT(lines, 2.5f) << "the caption wraps a few letters a line at font scale " << scale;
  }
}

// A status message longer than the status bar at a larger font: it is cut short of the
// font-scale steps at the right, not drawn over them (every glyph of the red message that
// shows lies left of the steps' first glyph).
TEST(UiLayout, ALongStatusMessageStopsShortOfTheFontScaleSteps) {
  LayoutApp app({1280, 800});
  app.ui.scale.user = 1.5f;
  app.state.message = "error: " + std::string(200, 'x') + ": not attached";
  app.Frames(3);
  const ImDrawList* list = LayoutApp::Window("##status")->DrawList;
  const ImU32 red = ImGui::ColorConvertFloat4ToU32(ImVec4(1.0f, 0.4f, 0.4f, 1.0f));  // errors
  float red_right = 0, steps_left = 1e9f;
  for (const ImDrawCmd& cmd : list->CmdBuffer)
    for (unsigned i = 0; i < cmd.ElemCount; ++i) {
      const ImDrawVert& v = list->VtxBuffer[cmd.VtxOffset + list->IdxBuffer[cmd.IdxOffset + i]];
      if (v.col == red)
        red_right = std::max(red_right, std::min(v.pos.x, cmd.ClipRect.z));
      else if (v.col == ImGui::GetColorU32(ImGuiCol_Text))
        steps_left = std::min(steps_left, v.pos.x);
    }
  ASSERT_GT(red_right, 0) << "no message drawn";
  ASSERT_LT(steps_left, 1280) << "no font-scale steps drawn";
  EXPECT_LT(red_right, steps_left) << "the message runs over the font-scale steps";
}

// A path field at the largest font scale: the field starts past its label, never over it
// (the mouse on the label's last letter is not over the field), as at the default scale.
struct PathFieldPanel : Panel {
  const char* Title() const override { return "Path"; }
  void Draw(UiContext&) override {
    if (BeginPanel(*this)) {
      label_at = ImGui::GetCursorScreenPos();
      PathField("Folder", "##folder", "the pictures' folder/", &folder, {});
    }
    ImGui::End();
  }
  std::string folder;
  ImVec2 label_at;
};

TEST(UiLayout, APathFieldStartsPastItsLabelAtEveryFontScale) {
  LayoutApp app({1280, 800});
  PathFieldPanel panel;
  panel.tiled = true;
  panel.tile_pos = ImVec2(0, 40);
  panel.tile_size = ImVec2(500, 200);
  for (const float scale : {1.0f, kFontScaleSteps[std::size(kFontScaleSteps) - 1]}) {
    float applied = 0;
    ApplyUiScale(scale, &applied);
    testing::ImGuiHeadless::DrawPanel(app.ui, panel, {500, 200});  // where the label is
    const auto hovered_at = [&](float x) {
      ImGui::GetIO().MousePos =
          ImVec2(panel.label_at.x + x, panel.label_at.y + 0.5f * ImGui::GetFontSize());
      for (int i = 0; i < 2; ++i) testing::ImGuiHeadless::DrawPanel(app.ui, panel, {500, 200});
      return GImGui->HoveredId == LayoutApp::Window("Path")->GetID("##folder");
    };
    const float label = ImGui::CalcTextSize("Folder").x;
    EXPECT_FALSE(hovered_at(label - 2)) << "the field over its label at font scale " << scale;
    EXPECT_TRUE(hovered_at(label + 4 * ImGui::GetFontSize())) << "the field, at " << scale;
  }
}

// The font scale steps (issue 58, item 8): A+ and A- in the status bar and Ctrl+= / Ctrl+-
// move one step each; the View menu only says where they are, so a stray click there (where
// a slider was) changes nothing.
TEST(UiLayout, FontScaleStepsFromTheStatusBarNotTheViewMenu) {
  EXPECT_EQ(StepFontScale(1.0f, +1), 1.25f);
  EXPECT_EQ(StepFontScale(2.0f, +1), 2.0f);
  EXPECT_EQ(StepFontScale(0.75f, -1), 0.75f);
  EXPECT_EQ(StepFontScale(1.1f, -1), 1.0f);  // between steps: the next one that way
  EXPECT_EQ(StepFontScale(1.1f, +1), 1.25f);
  LayoutApp app({1280, 800});
  // The View menu: a click on each of its last rows, where the slider was.
  const float line = ImGui::GetFrameHeight();
  app.Click(ImVec2(ImGui::CalcTextSize("File").x + ImGui::CalcTextSize("Edit").x + 50, line / 2));
  ImGuiWindow* view = ImGui::FindWindowByName("##Menu_00");
  ASSERT_NE(view, nullptr);
  ASSERT_TRUE(view->Active) << "the View menu is open";
  // Two font sizes in from the left, on the last row: inside the slider's frame as it was.
  const ImVec2 bottom(view->Pos.x + ImGui::GetStyle().WindowPadding.x + 2 * ImGui::GetFontSize(),
                      view->Pos.y + view->Size.y - 0.6f * line);
  app.Click(bottom);
  EXPECT_EQ(app.ui.scale.user, 1.0f) << "a stray click in the View menu changed the font scale";
  app.MouseTo(5, 400);
  app.Frames(2);

  const auto press = [&](const char* button) {
    testing::Activate(app, "##status", button);
    app.Frames(2);
  };
  press("A+");
  press("A+");
  EXPECT_EQ(app.ui.scale.user, 1.5f);
  EXPECT_NEAR(ImGui::GetFontSize(), 1.5f * 13, 0.5f);
  press("A-");
  EXPECT_EQ(app.ui.scale.user, 1.25f);
  app.CtrlTap('=');
  EXPECT_EQ(app.ui.scale.user, 1.5f);
  app.CtrlTap('-');
  app.CtrlTap('-');
  EXPECT_EQ(app.ui.scale.user, 1.0f);
  for (int i = 0; i < 8; ++i) app.CtrlTap('=');
  EXPECT_EQ(app.ui.scale.user, 2.0f) << "held at the largest step";
  app.CtrlTap('0');
  EXPECT_EQ(app.ui.scale.user, 1.0f);
}

// A key's press or release, as the window's callback queues it.
void PushKey(InputQueue* queue, int code, bool down) {
  InputEvent e;
  e.kind = InputEvent::Kind::kKey;
  e.code = code;
  e.down = down;
  queue->Push(e);
}

// Six Ctrl+key chords typed faster than the frames, in the order xdotool sends them (Ctrl
// released before the key), all queued before the next frame: each one arrives.
TEST(UiLayout, SixFastCtrlChordsAllArrive) {
  LayoutApp app({1280, 800});
  InputQueue queue;
  const auto key = [&](int code, bool down) { PushKey(&queue, code, down); };
  for (int k : {'-', '=', '=', '=', '=', '='}) {
    key(kKeyLeftControl, true);
    key(k, true);
    key(kKeyLeftControl, false);
    key(k, false);
  }
  app.Drain(&queue);
  EXPECT_EQ(app.ui.scale.user, 2.0f) << "0.75 after Ctrl+-, then five steps up";
}

// Six Ctrl+key chords whose Ctrl is let go right after the key goes down, as fast typing
// and xdotool do: Ctrl's press reaches one frame, the key's press and Ctrl's release the
// next. Each chord applies (Ctrl was seen released in the frame its key went down).
TEST(UiLayout, ACtrlChordLetGoCtrlFirstWithinAFrameStillApplies) {
  LayoutApp app({1280, 800});
  InputQueue queue;
  const auto key = [&](int code, bool down) { PushKey(&queue, code, down); };
  for (int k : {'-', '=', '=', '=', '=', '='}) {
    key(kKeyLeftControl, true);
    queue.NextFrame(&app.input);  // Ctrl's press, a frame before the rest arrives
    app.Frame();
    key(k, true);
    key(kKeyLeftControl, false);
    key(k, false);
    app.Drain(&queue);
  }
  EXPECT_EQ(app.ui.scale.user, 2.0f) << "0.75 after Ctrl+-, then five steps up";
}

// At the largest font scale on a 1280 x 800 window the Grouping panel keeps its table and
// sliders readable: each column as wide as its header (the table scrolls sideways instead),
// and the sliders wide enough for their values (their labels above them when the panel is
// too narrow for both); the Pipeline panel's settings too.
TEST(UiLayout, AtTheLargestFontScaleTheGroupingTableAndSlidersKeepTheirText) {
  LayoutApp app({1280, 800});
  app.ui.scale.user = kFontScaleSteps[std::size(kFontScaleSteps) - 1];
  app.Frames(4);
  const float em = ImGui::GetFontSize();
  ASSERT_NEAR(em, 26, 0.5f);
  ImGuiWindow* grouping = LayoutApp::Window("Grouping");
  ImGuiTable* table = ImGui::TableFindByID(grouping->GetID("groups"));
  ASSERT_NE(table, nullptr);
  // Scrolled down the panel until the table is drawn (below the sliders and messages).
  for (float y = 0; y <= grouping->ScrollMax.y && table->LastFrameActive < ImGui::GetFrameCount();
       y += 100) {
    ImGui::SetScrollY(grouping, y);
    app.Frames(3);
  }
  ASSERT_EQ(table->LastFrameActive, ImGui::GetFrameCount()) << "the table is drawn";
  const char* headers[] = {"group", "triangles", "texels", "texel m"};
  for (int c = 0; c < table->ColumnsCount; ++c)
    for (int c = 0; c < table->ColumnsCount; ++c)
      EXPECT_GE(table->Columns[c].WidthGiven, ImGui::CalcTextSize(headers[c]).x)
          << headers[c] << " cut in a " << grouping->Size.x << " px panel";
  EXPECT_GE(std::stof(app.ReportOf("Grouping", "angle slider px")), 5 * em);  // "90.0" and room
  EXPECT_LE(std::stof(app.ReportOf("Grouping", "angle slider px")),
            grouping->ContentRegionRect.GetWidth() + 0.5f);
  // The same at the default scale: the labels stay beside their sliders.
  app.ui.scale.user = 1;
  app.Frames(4);
  EXPECT_GE(std::stof(app.ReportOf("Grouping", "angle slider px")), 5 * 13.0f);
}

}  // namespace
}  // namespace fresco

namespace fresco {
namespace {

// Draws `title`'s panel alone as a tile `width` pixels wide at font scale 1.5, a few frames.
Panel& DrawNarrowAtLargerFont(LayoutApp& app, const std::string& title, float width) {
  Panel* panel = nullptr;
  for (auto& p : app.panels)
    if (title == p->Title()) panel = p.get();
  EXPECT_NE(panel, nullptr) << title;
  float applied = 0;
  ApplyUiScale(1.5f, &applied);
  panel->open = true;
  panel->tiled = true;
  panel->tile_pos = ImVec2(0, 40);
  panel->tile_size = ImVec2(width, 700);
  for (int i = 0; i < 3; ++i) testing::ImGuiHeadless::DrawPanel(app.ui, *panel, {width, 700});
  return *panel;
}

// The calibration light's words in a narrow panel at font scale 1.5: whole (every glyph of
// "NOT ENOUGH DATA" inside the panel), on at most two lines, not a few letters a line. Before:
// squeezed into the controls' column (27 % of the panel: 60 pixels of 240), 4 lines of
// 3-4 letters each.
TEST(UiLayout, TheCalibrationLightsWordsStayWholeInANarrowPanelAtALargerFont) {
  LayoutApp app({1280, 800});
  for (const float width : {240.0f, 300.0f, 600.0f, 1100.0f}) {
    DrawNarrowAtLargerFont(app, kCalibrationPanelTitle, width);
    ImGuiWindow* window = LayoutApp::Window(kCalibrationPanelTitle);
    ASSERT_NE(window, nullptr);
    const ImDrawList* list = window->DrawList;
    const ImU32 red = ImGui::ColorConvertFloat4ToU32(ImVec4(0.9f, 0.2f, 0.2f, 1));  // the light
    float left = 1e9f, right = 0, top = 1e9f, bottom = 0, clip_right = 0;
    for (const ImDrawCmd& cmd : list->CmdBuffer)
      for (unsigned i = 0; i < cmd.ElemCount; ++i) {
        const ImDrawVert& v = list->VtxBuffer[cmd.VtxOffset + list->IdxBuffer[cmd.IdxOffset + i]];
        if (v.col != red || v.uv.x == ImGui::GetIO().Fonts->TexUvWhitePixel.x) continue;
        left = std::min(left, v.pos.x), right = std::max(right, v.pos.x);
        top = std::min(top, v.pos.y), bottom = std::max(bottom, v.pos.y);
        clip_right = cmd.ClipRect.z;
      }
    ASSERT_GT(right, 0) << "the words not drawn at all (beside the lights, past the edge of the "
                           "controls' column), width "
                        << width;
    EXPECT_LE(right, clip_right) << "the words cut at the panel's edge, width " << width;
    EXPECT_LE(bottom - top, 2.2f * ImGui::GetTextLineHeight()) << "width " << width;
    EXPECT_GE(right - left, ImGui::CalcTextSize("NOT ENOUGH").x) << "a few letters a line";
  }
}

// A seek under way in a narrow Pipeline panel at font scale 1.5: Stop stays inside the panel,
// and the progress text is shown whole, in the bar where it fits, else on its own lines below
// it. Before: the bar was the panel less 60 pixels (159 of a 260-pixel panel, 239 of 340)
// and cut its 410-pixel text.
TEST(UiLayout, TheSeekProgressTextIsWholeInANarrowPanelAtALargerFont) {
  LayoutApp app({1280, 800});
  auto seeking = std::make_shared<RunnerSnapshot>(*app.runner.Snapshot());
  seeking->seek_target = 90;
  seeking->seek_from = 0;
  seeking->frame = 30;
  app.ui.snapshot = seeking;
  for (const float width : {260.0f, 340.0f, 700.0f}) {
    Panel& panel = DrawNarrowAtLargerFont(app, "Pipeline", width);
    std::map<std::string, std::string> report = panel.Report();
    const std::string text = report["seek text"];
    ASSERT_NE(text.find("frame"), std::string::npos) << text;
    const float bar = std::stof(report["seek bar width"]);
    const float lines = std::stof(report["seek text lines"]);
    const float needed = ImGui::CalcTextSize(text.c_str()).x;
    if (lines == 0) {
      EXPECT_LE(needed, bar) << "the text cut in a " << bar << "-pixel bar, width " << width;
    } else {
      EXPECT_LE(lines, 3.2f) << "width " << width;
    }
    EXPECT_LE(std::stof(report["seek stop right"]), std::stof(report["panel right"]) + 0.5f)
        << "Stop runs out of the panel, width " << width;
  }
}

}  // namespace
}  // namespace fresco

namespace fresco {
namespace {

// The glyphs drawn in `window` in the text colour (each a quad of four vertices off the font
// atlas' white pixel), and the leftmost x of any.
int TextGlyphs(ImGuiWindow* window, float* left) {
  const ImU32 text = ImGui::GetColorU32(ImGuiCol_Text);
  const ImVec2 white = ImGui::GetIO().Fonts->TexUvWhitePixel;
  int vertices = 0;
  *left = 1e9f;
  for (const ImDrawVert& v : window->DrawList->VtxBuffer)
    if (v.col == text && (v.uv.x != white.x || v.uv.y != white.y)) {
      ++vertices;
      *left = std::min(*left, v.pos.x);
    }
  return vertices / 4;
}

// COLMAP's progress in the Poses panel's controls column (360 pixels at 1920 x 1080): every
// letter of "step 1/8 feature_extractor 30/61 images: 30 s elapsed, about 31 s left in this
// step" is drawn, in the bar where it fits, else below it. Before: ImGui's bar right-aligned
// the 470-pixel text and cut its start, showing "images: 30 s elapsed, ..." without the step
// or the count.
TEST(UiLayout, COLMAPsProgressTextIsWholeInThePosesControlsColumn) {
  testing::ImGuiHeadless imgui;
  const std::string log = testing::MakeTempDir("colmap-progress") + "/feature_extractor.log";
  std::ofstream(log) << "Processed file [29/61]\nProcessed file [30/61]\n";
  PosesSnapshot snap;
  snap.busy = true;
  snap.step = 1;
  snap.steps = 8;
  snap.step_name = "feature_extractor";
  snap.step_log = log;
  snap.step_started = snap.started = std::chrono::steady_clock::now() - std::chrono::seconds(30);
  const std::string expected =
      "step 1/8 feature_extractor 30/61 images: 30 s elapsed, about 31 s left in this step";
  const int letters = static_cast<int>(
      std::count_if(expected.begin(), expected.end(), [](char c) { return c != ' '; }));
  for (const float width : {360.0f, 900.0f}) {
    for (int frame = 0; frame < 2; ++frame) {
      ImGui::NewFrame();
      ImGui::SetNextWindowPos(ImVec2(100, 100));
      ImGui::SetNextWindowSize(ImVec2(width, 300));
      ImGui::Begin("COLMAP progress");
      ColmapProgressBar(snap);
      ImGui::End();
      ImGui::Render();
    }
    ImGuiWindow* window = ImGui::FindWindowByName("COLMAP progress");
    ASSERT_NE(window, nullptr);
    float left = 0;
    EXPECT_GE(TextGlyphs(window, &left), letters) << "letters cut off, width " << width;
    EXPECT_GE(left, window->InnerClipRect.Min.x) << "width " << width;
  }
}

}  // namespace
}  // namespace fresco

namespace fresco {
namespace {

// Two path fields as the Calibration panel has them (Folder, then Attach), drawn in a window
// with the mouse at `mouse` (button down or not); returns the rectangle of each field's "..."
// button when its list is closed.
struct TwoPathFields {
  std::string folder, attach, last_folder;
  ImVec4 folder_button, attach_button;
  void Frame(ImVec2 mouse, bool down) {
    ImGuiIO& io = ImGui::GetIO();
    io.MousePos = mouse;
    io.MouseDown[0] = down;
    ImGui::NewFrame();
    ImGui::SetNextWindowPos(ImVec2(0, 0));
    ImGui::SetNextWindowSize(ImVec2(600, 400));
    ImGui::Begin("two path fields");
    PathField("Folder", "##folder", "", &folder, {.last_folder = &last_folder});
    folder_button = ItemRect();
    PathField("Attach", "##attach", "", &attach, {.last_folder = &last_folder});
    attach_button = ItemRect();
    ImGui::End();
    ImGui::Render();
  }
  static ImVec4 ItemRect() {
    return {ImGui::GetItemRectMin().x, ImGui::GetItemRectMin().y, ImGui::GetItemRectMax().x,
            ImGui::GetItemRectMax().y};
  }
  void Click(ImVec2 at) {
    Frame(at, false);
    Frame(at, true);
    Frame(at, false);
  }
};

// With the Folder field's "..." list open, a click into the Attach field closes the list and
// puts the cursor there: what is typed next lands in it. Before: the click only closed the
// list (ImGui gives a click outside an open list to the list alone), no field was active and
// the text typed was lost.
TEST(UiLayout, AClickIntoAnotherFieldWhileAPathListIsOpenTakesTheTyping) {
  testing::ImGuiHeadless imgui;
  TwoPathFields fields;
  fields.last_folder = testing::MakeTempDir("path-list") + "/";
  fields.Frame(ImVec2(-1, -1), false);
  fields.Frame(ImVec2(-1, -1), false);
  const ImVec4 folder = fields.folder_button, attach = fields.attach_button;
  fields.Click(ImVec2((folder.x + folder.z) / 2, (folder.y + folder.w) / 2));
  ASSERT_FALSE(GImGui->OpenPopupStack.empty()) << "the Folder field's list opened";
  // Into the Attach field, just left of its "..." button.
  fields.Click(ImVec2(attach.x - 30, (attach.y + attach.w) / 2));
  EXPECT_TRUE(GImGui->OpenPopupStack.empty()) << "the list closed";
  ImGui::GetIO().AddInputCharacter('x');
  fields.Frame(ImVec2(attach.x - 30, (attach.y + attach.w) / 2), false);
  fields.Frame(ImVec2(attach.x - 30, (attach.y + attach.w) / 2), false);
  EXPECT_EQ(fields.attach, "x") << "the text typed after the click";
  EXPECT_EQ(fields.folder, fields.last_folder) << "the Folder field as its list left it";
}

}  // namespace
}  // namespace fresco
