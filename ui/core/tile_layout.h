// The app's tiled layout, pure logic (no ImGui): a tree of splits whose leaves are panels.
// Every split has a draggable splitter between its two sides; a closed panel gives its
// space to its neighbour; one panel can be maximised over the whole band and restored; two
// panels can swap places. A tab group shares one place between several sides (a panel or a
// subtree of them): one shows at a time, the others stay open behind their tabs, and the
// strip of tabs appears above it while two or more are open.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "ui/core/layout.h"

namespace fresco {

class TileLayout {
 public:
  // A leaf showing panel `title`; a split of `a` and `b`, side by side (`stacked` false) or
  // `a` above `b`, where `a` takes `fraction` of the space. Return the node's index.
  int Leaf(const std::string& title);
  int Split(bool stacked, float fraction, int a, int b);
  // A tab group of `sides` (nodes); a side that is a subtree is named by `name` on its tab,
  // a panel by its title. The first side shows until another is chosen (ShowTab).
  struct TabSide {
    int node = -1;
    std::string name;  // "" for a panel: its title
  };
  int Tabs(const std::vector<TabSide>& sides);
  // Split `split` uses `fraction` instead of its own while its second side is a tab group
  // showing other than its first side (a tool in front gets more room than the stage row).
  void SetToolFraction(int split, float fraction);
  void SetRoot(int node) { root_ = node; }

  struct Tile {
    std::string panel;
    LayoutRect rect;
  };
  struct Splitter {
    int node = -1;         // the split it moves
    bool stacked = false;  // true: a horizontal bar moved up and down
    LayoutRect rect;       // the bar (the gap between the two sides)
    float extent = 0;      // the split's width (or height), pixels: drag px / extent = fraction
    bool tool = false;     // it moves the split's tool fraction (SetToolFraction)
  };
  // A tab group's strip (drawn while two or more of its sides are open): its open sides'
  // names in order and which one shows.
  struct TabStrip {
    int node = -1;
    LayoutRect rect;
    std::vector<std::string> names;
    int shown = 0;  // index into names
  };
  // The panels' rectangles within `band`, `gap_px` apart, and the splitters; panels for
  // which `is_open` is false take no space. A maximised panel (when open) fills the band
  // alone, without splitters. A tab group places only the side it shows, below its strip of
  // `strip_px` (appended to `strips` when given).
  void Compute(const LayoutRect& band, float gap_px,
               const std::function<bool(const std::string&)>& is_open, std::vector<Tile>* tiles,
               std::vector<Splitter>* splitters, std::vector<TabStrip>* strips = nullptr,
               float strip_px = 0) const;
  // Moves a splitter by `delta_px`, keeping both sides at least `min_px` (when they can).
  void Drag(const Splitter& splitter, float delta_px, float min_px);

  bool Contains(const std::string& title) const;
  // Makes every tab group holding panel `title` show the side that holds it (a panel just
  // opened comes to the front); false when no tab group holds it.
  bool ShowTab(const std::string& title);
  // Tab group `node` shows its side named `name` (a click on its tab).
  void ShowTabNamed(int node, const std::string& name);
  // "" when none is maximised.
  const std::string& maximised() const { return maximised_; }
  void ToggleMaximised(const std::string& title);

  // Panels `a` and `b` (both tiled) swap their tiles; false when either is not tiled.
  bool Swap(const std::string& a, const std::string& b);

  // Every split's fraction, in node order (to save and restore a layout of the same tree).
  std::vector<float> Fractions() const;
  void SetFractions(const std::vector<float>& fractions);
  // The panel of every leaf, in node order (to save and restore swapped places); SetPanels
  // takes only a reordering of the same panels, else changes nothing and returns false.
  std::vector<std::string> Panels() const;
  bool SetPanels(const std::vector<std::string>& panels);

 private:
  struct Node {
    std::string panel;  // leaves
    bool stacked = false;
    float fraction = 0.5f;
    float tool_fraction = -1;   // SetToolFraction; < 0: none
    int a = -1, b = -1;         // splits
    std::vector<TabSide> tabs;  // tab groups
    std::string shown;          // ... the side in front (its name), "" for the first open
    bool IsLeaf() const { return a < 0 && tabs.empty(); }
  };
  // What Compute fills.
  struct Placed {
    std::vector<Tile>* tiles;
    std::vector<Splitter>* splitters;
    std::vector<TabStrip>* strips;
    float gap_px, strip_px;
  };
  bool AnyOpen(int node, const std::function<bool(const std::string&)>& is_open) const;
  bool Holds(int node, const std::string& title) const;
  std::string SideName(const TabSide& side) const;
  // Tab group `node`'s side in front (an index into its tabs), -1 when none is open or
  // `node` is no tab group.
  int ShownSide(int node, const std::function<bool(const std::string&)>& is_open) const;
  void Place(int node, const LayoutRect& rect,
             const std::function<bool(const std::string&)>& is_open, const Placed& out) const;
  void PlaceTabs(int node, const LayoutRect& rect,
                 const std::function<bool(const std::string&)>& is_open, const Placed& out) const;

  std::vector<Node> nodes_;
  int root_ = -1;
  std::string maximised_;
};

// The app's default: the 3D view large in the centre with the input frame and the painted
// buffers beside it, the stage panels in a row below, project, pipeline and timing on the
// left, grouping and misalignment on the right. The tools (Poses, Calibration, New project)
// open as tabs beside the stage row's tab, in its place below the 3D view.
TileLayout DefaultTileLayout();

}  // namespace fresco
