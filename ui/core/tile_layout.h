// The app's tiled layout, pure logic (no ImGui): a tree of splits whose leaves are panels.
// Every split has a draggable splitter between its two sides; a closed panel gives its
// space to its neighbour; one panel can be maximised over the whole band and restored; two
// panels can swap places.
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
  };
  // The panels' rectangles within `band`, `gap_px` apart, and the splitters; panels for
  // which `is_open` is false take no space. A maximised panel (when open) fills the band
  // alone, without splitters.
  void Compute(const LayoutRect& band, float gap_px,
               const std::function<bool(const std::string&)>& is_open, std::vector<Tile>* tiles,
               std::vector<Splitter>* splitters) const;
  // Moves a splitter by `delta_px`, keeping both sides at least `min_px` (when they can).
  void Drag(const Splitter& splitter, float delta_px, float min_px);

  bool Contains(const std::string& title) const;
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
    int a = -1, b = -1;  // splits
  };
  bool AnyOpen(int node, const std::function<bool(const std::string&)>& is_open) const;
  void Place(int node, const LayoutRect& rect, float gap_px,
             const std::function<bool(const std::string&)>& is_open, std::vector<Tile>* tiles,
             std::vector<Splitter>* splitters) const;

  std::vector<Node> nodes_;
  int root_ = -1;
  std::string maximised_;
};

// The app's default: the 3D view large in the centre with the input frame and the painted
// buffers beside it, the stage panels in a row below, project, pipeline and timing on the
// left, grouping and misalignment on the right.
TileLayout DefaultTileLayout();

}  // namespace fresco
