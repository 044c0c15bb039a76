// The panel framework: every panel is a struct with its own state and a Draw() that starts
// with `if (!ImGui::Begin(...)) { ImGui::End(); return; }`. Panels read the runner's latest
// immutable snapshot and edit the AppState; they never call GL: images go through
// ImageTextures and the 3D view through ViewportRenderer, which the GL app implements and
// tests replace with null versions. Adding a panel = a new file in ui/panels/ and one line
// in ui/panels/panel_registry.cc.
#pragma once

#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <imgui.h>
#include <opencv2/core.hpp>

#include "ui/core/app_state.h"
#include "ui/core/calibration_runner.h"
#include "ui/core/dropped_file.h"
#include "ui/core/orbit_frame.h"
#include "ui/core/pipeline_runner.h"
#include "ui/core/poses_runner.h"
#include "ui/core/tile_layout.h"
#include "ui/core/ui_scale.h"

namespace fresco {

// Textures for images shown in panels, cached by key and re-uploaded when `version` changes.
// Images: CV_8UC1, CV_8UC3 (BGR) or CV_8UC4 (BGRA).
class ImageTextures {
 public:
  virtual ~ImageTextures() = default;
  virtual ImTextureID Get(const std::string& key, const cv::Mat& image, uint64_t version) = 0;
};

// How the 3D viewport looks at the model.
struct ViewportView {
  enum class Mode { kPainted, kGroups, kProjected };
  Mode mode = Mode::kPainted;
  float yaw_deg = 30, pitch_deg = 25;  // orbit angles
  float distance_m = 0;                // 0 = fit the model
  float target[3] = {0, 0, 0};         // orbit centre, world
  bool target_set = false;
  OrbitFrame orbit;                     // which way is up (from the capture's poses)
  uint64_t orbit_geometry_version = 0;  // the geometry `orbit` was taken from (0: none yet)
  bool show_path = true, show_frustum = true;
  bool view_layers = true;  // painted mode: blend the view-dependent layers (when painted)
  // After a pose verification (Poses panel): COLMAP's camera centres under the alignment each
  // frame was judged by, as a path beside the given one, each flagged frame's offset from its
  // given centre marked (world, metres).
  struct PoseCheckMark {
    Eigen::Vector3d given, colmap;
    bool flagged = false;
  };
  std::vector<PoseCheckMark> pose_check;
  bool show_pose_check = true;
};

// Draws the model (painted textures, group colours or the current frame projected onto it),
// the current camera's frustum and the path into an offscreen image of w x h pixels.
class ViewportRenderer {
 public:
  virtual ~ViewportRenderer() = default;
  virtual ImTextureID Render(const RunnerSnapshot& snapshot, const AppState& state,
                             ViewportView* view, int width, int height) = 0;
  // The triangle under pixel (x, y) of the last Render, -1 for none.
  virtual int Pick(int x, int y) = 0;
};

struct UiContext {
  AppState* state = nullptr;
  PipelineRunner* runner = nullptr;
  CalibrationRunner* calibration = nullptr;
  ImageTextures* textures = nullptr;
  ViewportRenderer* viewport = nullptr;
  std::shared_ptr<const RunnerSnapshot> snapshot;  // this UI frame's view of the worker
  bool request_quit = false;
  PosesRunner* poses = nullptr;  // the COLMAP worker (Poses panel)
  // A project just opened: the worker's first snapshot after `opened_version` says whether
  // its files could be read (app_frame.cc turns a failure into one error).
  bool open_pending = false;
  uint64_t opened_version = 0;
  // Where the tiled panels go (splitters, maximise); panels not in it float.
  TileLayout layout = DefaultTileLayout();
  bool new_project_requested = false;  // File > New project...: the app frame opens the form
  std::vector<std::string> dropped_paths = {};  // dropped on the window (DropPaths), not yet placed
  UiScale scale = {};                           // the monitor's and the user's (View > font scale)
  float scale_applied = 0;     // what the fonts and style were last built for (ApplyUiScale)
  std::string menu_path = {};  // File > Open... / Save As...: the path typed there
  std::string swapping = {};   // the panel whose "swap places" menu is open
  std::set<std::string> open_last_frame = {};  // panels open (or busy) last frame
  // Each tab of a tab group's strip as drawn this frame (screen pixels), by its name.
  std::map<std::string, LayoutRect> tabs_drawn = {};
};

class Panel {
 public:
  virtual ~Panel() = default;
  // The panel's name: in the View menu, the tiled layout, layout files, and its ImGui
  // window's ID (PanelWindowId), whatever its title bar shows.
  virtual const char* Title() const = 0;
  // A shorter title for a title bar too narrow for Title() (FittedTitle); Title() if none.
  virtual const char* ShortTitle() const { return Title(); }
  virtual void Draw(UiContext& ui) = 0;
  // What the panel shows, for `fresco gui --screenshot`'s FILE.json (name -> value).
  virtual std::map<std::string, std::string> Report() const { return {}; }
  // A scene, video, camera or poses file dropped on the window for this panel's path fields
  // (PlaceDroppedPaths): true when the panel took it.
  virtual bool AcceptDrop(const DroppedFile&) { return false; }
  // Work under way that hiding the panel must not leave running unseen (a COLMAP run): the
  // app frame draws a busy panel even when hidden from the View menu, and the panel decides
  // what hiding means (the New project form: as closing it, it cancels the run and shows
  // that it did).
  virtual bool Busy() const { return false; }
  bool open = true;
  // Where a floating panel starts, in a 1600 x 1000 window (scaled to the real size).
  ImVec2 default_pos = ImVec2(0, 20), default_size = ImVec2(400, 300);
  // Set by the app frame before each frame: the panel's tile in the layout (a tiled panel
  // neither moves nor resizes itself), or floating.
  bool tiled = false;
  ImVec2 tile_pos, tile_size;
  // A double-click on a tiled panel's title bar: the app frame maximises or restores it.
  bool maximise_requested = false;
  // A right-click on it: the app frame offers the other tiled panels to swap places with.
  bool swap_menu_requested = false;
};

// Every panel, in menu order (panel_registry.cc).
std::vector<std::unique_ptr<Panel>> MakePanels();

// The status bar at the bottom of the window (app_frame.cc), pixels: a line of text and its
// padding (24 at scale 1).
inline float StatusBarHeight() { return std::round(ImGui::GetFrameHeight() + 5); }

// Helpers for panels.
// Starts the panel's window: in its tile when tiled (a double-click on the title bar asks to
// maximise or restore it); else at its default place the first time (scaled to the
// display), its title bar kept below the menu bar and on screen.
bool BeginPanel(Panel& panel);
// A panel's ImGui window is named "shown title###Title()": its ID is this, whatever the
// title bar shows (ImGui::FindWindowByName(PanelWindowId(title)) finds it).
inline std::string PanelWindowId(const std::string& title) { return "###" + title; }
// What a title bar `width` pixels wide shows of the panel's title: Title() where it fits,
// else ShortTitle(), else that cut short with ".." (the title bar's tooltip shows it whole).
std::string FittedTitle(const Panel& panel, float width);
// The same for a tool panel that shows a worker (Poses, Calibration; tiled as a tab below the
// 3D view): false, with the window already ended, when there is no worker (it says so).
bool BeginOverlayPanel(Panel& panel, bool has_worker, const char* worker);
// An image scaled to fit `max_width` (0 = the available width), keeping its aspect.
void ShowImage(UiContext& ui, const std::string& key, const cv::Mat& image, uint64_t version,
               float max_width = 0);
// The frame the user is looking at: a seek's target while it runs, else the last painted.
int ShownFrame(const RunnerSnapshot& snap);
// "frame 12", "seeking to frame 40: at 17", "no frame painted yet"; going back, "seeking to
// frame 13: from the state saved before frame 10" (or ": reopening" without one).
std::string FrameLabel(const RunnerSnapshot& snap);
// The worker's status, with the time of a step of opening still under way counted to now
// ("adjusting poses 120/246, 40 s elapsed, about 42 s left"; RunnerSnapshot::step_text).
std::string StatusText(const RunnerSnapshot& snap);
// Layout in narrow panels: the next item's width so that `following` (a button's label on
// the same line after it, or a widget's own label) still fits, at least `min_px`; and
// SameLine only when an item `next_width` wide fits after the last one (else a new line).
void FitNextItem(const char* following = nullptr, float min_px = 40);
void SameLineIfFits(float next_width);
// After a form's label (a path field's "Folder", "Save to"): the field on the same line, in
// the form's column (80 pixels at the default font, growing with the font scale), or just past
// the label where it is wider, never over it.
void SameLineInFieldColumn();
// A labelled widget (slider, drag, combo) that keeps its value readable in a narrow panel or
// at a large font scale: when the width it has beside its label (CalcItemWidth) is less than
// kMinFieldEm font sizes, `label` goes on a line of its own above and the widget takes the
// whole width. Returns the label to pass to the widget ("##" + label when it went above).
inline constexpr float kMinFieldEm = 5;
std::string FitLabelledItem(const std::string& label);
float ButtonWidth(const char* label);
// A two-column table of metrics.
void ShowMetrics(const std::map<std::string, double>& metrics);
// A progress bar `width` wide (<= 0: the available width less that) with `text` in it where
// the text fits, else the percentage in it and the text whole, wrapped, on the lines below
// (ImGui's bar would cut the text's start). Returns the lines below (0: the text is in the bar).
float ProgressBarWithText(float fraction, const std::string& text, float width = 0);
// A COLMAP run under way (PosesRunner): a bar over its steps, with the step's name, how far
// COLMAP has got in it, the elapsed time and an estimate; nothing when the worker is idle.
void ColmapProgressBar(const PosesSnapshot& snap);

}  // namespace fresco
