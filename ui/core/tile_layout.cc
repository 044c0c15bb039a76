#include "ui/core/tile_layout.h"

#include <algorithm>
#include <cmath>

namespace fresco {

int TileLayout::Leaf(const std::string& title) {
  Node n;
  n.panel = title;
  nodes_.push_back(n);
  return static_cast<int>(nodes_.size()) - 1;
}

int TileLayout::Split(bool stacked, float fraction, int a, int b) {
  Node n;
  n.stacked = stacked;
  n.fraction = fraction;
  n.a = a;
  n.b = b;
  nodes_.push_back(n);
  return static_cast<int>(nodes_.size()) - 1;
}

int TileLayout::Tabs(const std::vector<TabSide>& sides) {
  Node n;
  n.tabs = sides;
  nodes_.push_back(n);
  return static_cast<int>(nodes_.size()) - 1;
}

void TileLayout::SetToolFraction(int split, float fraction) {
  nodes_[split].tool_fraction = fraction;
}

bool TileLayout::AnyOpen(int node, const std::function<bool(const std::string&)>& is_open) const {
  const Node& n = nodes_[node];
  if (n.IsLeaf()) return is_open(n.panel);
  for (const TabSide& side : n.tabs)
    if (AnyOpen(side.node, is_open)) return true;
  return n.a >= 0 && (AnyOpen(n.a, is_open) || AnyOpen(n.b, is_open));
}

bool TileLayout::Holds(int node, const std::string& title) const {
  const Node& n = nodes_[node];
  if (n.IsLeaf()) return n.panel == title;
  for (const TabSide& side : n.tabs)
    if (Holds(side.node, title)) return true;
  return n.a >= 0 && (Holds(n.a, title) || Holds(n.b, title));
}

std::string TileLayout::SideName(const TabSide& side) const {
  return side.name.empty() ? nodes_[side.node].panel : side.name;
}

int TileLayout::ShownSide(int node, const std::function<bool(const std::string&)>& is_open) const {
  const Node& n = nodes_[node];
  int shown = -1;  // the chosen side when open, else the first open one
  for (size_t k = 0; k < n.tabs.size(); ++k)
    if (AnyOpen(n.tabs[k].node, is_open) && (shown < 0 || SideName(n.tabs[k]) == n.shown))
      shown = static_cast<int>(k);
  return shown;
}

void TileLayout::PlaceTabs(int node, const LayoutRect& rect,
                           const std::function<bool(const std::string&)>& is_open,
                           const Placed& out) const {
  const Node& n = nodes_[node];
  const int shown_side = ShownSide(node, is_open);
  if (shown_side < 0) return;
  const int shown = n.tabs[shown_side].node;
  TabStrip strip;
  strip.node = node;
  for (size_t k = 0; k < n.tabs.size(); ++k) {
    if (!AnyOpen(n.tabs[k].node, is_open)) continue;
    if (static_cast<int>(k) == shown_side) strip.shown = static_cast<int>(strip.names.size());
    strip.names.push_back(SideName(n.tabs[k]));
  }
  LayoutRect below = rect;
  if (strip.names.size() > 1) {  // one open side needs no tabs
    strip.rect = rect;
    strip.rect.h = std::min(out.strip_px, rect.h);
    below.y += strip.rect.h, below.h -= strip.rect.h;
    if (out.strips) out.strips->push_back(strip);
  }
  Place(shown, below, is_open, out);
}

void TileLayout::Place(int node, const LayoutRect& rect,
                       const std::function<bool(const std::string&)>& is_open,
                       const Placed& out) const {
  const Node& n = nodes_[node];
  if (n.IsLeaf()) {
    out.tiles->push_back({n.panel, rect});
    return;
  }
  if (!n.tabs.empty()) {
    PlaceTabs(node, rect, is_open, out);
    return;
  }
  const bool a_open = AnyOpen(n.a, is_open), b_open = AnyOpen(n.b, is_open);
  if (!a_open || !b_open) {  // one side closed: the other takes the whole rectangle
    if (a_open) Place(n.a, rect, is_open, out);
    if (b_open) Place(n.b, rect, is_open, out);
    return;
  }
  const float gap_px = out.gap_px;
  const bool tool =
      n.tool_fraction >= 0 && !nodes_[n.b].tabs.empty() && ShownSide(n.b, is_open) > 0;
  const float fraction = tool ? n.tool_fraction : n.fraction;
  const float extent = n.stacked ? rect.h : rect.w;
  const float first = std::max(0.0f, std::round(fraction * extent - 0.5f * gap_px));
  const float second = std::max(0.0f, extent - first - gap_px);
  LayoutRect ra = rect, rb = rect, bar = rect;
  if (n.stacked) {
    ra.h = first;
    bar.y = rect.y + first, bar.h = gap_px;
    rb.y = rect.y + first + gap_px, rb.h = second;
  } else {
    ra.w = first;
    bar.x = rect.x + first, bar.w = gap_px;
    rb.x = rect.x + first + gap_px, rb.w = second;
  }
  out.splitters->push_back({node, n.stacked, bar, extent, tool});
  Place(n.a, ra, is_open, out);
  Place(n.b, rb, is_open, out);
}

void TileLayout::Compute(const LayoutRect& band, float gap_px,
                         const std::function<bool(const std::string&)>& is_open,
                         std::vector<Tile>* tiles, std::vector<Splitter>* splitters,
                         std::vector<TabStrip>* strips, float strip_px) const {
  tiles->clear();
  splitters->clear();
  if (strips) strips->clear();
  if (!maximised_.empty() && is_open(maximised_)) {
    tiles->push_back({maximised_, band});
    return;
  }
  const Placed out{tiles, splitters, strips, gap_px, strip_px};
  if (root_ >= 0 && AnyOpen(root_, is_open)) Place(root_, band, is_open, out);
}

bool TileLayout::ShowTab(const std::string& title) {
  bool found = false;
  for (Node& n : nodes_)
    for (const TabSide& side : n.tabs)
      if (Holds(side.node, title)) {
        n.shown = SideName(side);
        found = true;
      }
  return found;
}

void TileLayout::ShowTabNamed(int node, const std::string& name) {
  if (node >= 0 && node < static_cast<int>(nodes_.size()) && !nodes_[node].tabs.empty())
    nodes_[node].shown = name;
}

void TileLayout::Drag(const Splitter& splitter, float delta_px, float min_px) {
  if (splitter.node < 0 || splitter.node >= static_cast<int>(nodes_.size())) return;
  if (splitter.extent <= 0) return;
  Node& n = nodes_[splitter.node];
  const float lo = std::min(0.5f, min_px / splitter.extent);
  float& fraction = splitter.tool ? n.tool_fraction : n.fraction;
  fraction = std::clamp(fraction + delta_px / splitter.extent, lo, 1.0f - lo);
}

bool TileLayout::Contains(const std::string& title) const {
  for (const Node& n : nodes_)
    if (n.IsLeaf() && n.panel == title) return true;
  return false;
}

void TileLayout::ToggleMaximised(const std::string& title) {
  maximised_ = maximised_ == title ? "" : title;
}

bool TileLayout::Swap(const std::string& a, const std::string& b) {
  Node* na = nullptr;
  Node* nb = nullptr;
  for (Node& n : nodes_) {
    if (!n.IsLeaf()) continue;
    if (n.panel == a) na = &n;
    if (n.panel == b) nb = &n;
  }
  if (!na || !nb) return false;
  std::swap(na->panel, nb->panel);
  return true;
}

std::vector<std::string> TileLayout::Panels() const {
  std::vector<std::string> panels;
  for (const Node& n : nodes_)
    if (n.IsLeaf()) panels.push_back(n.panel);
  return panels;
}

bool TileLayout::SetPanels(const std::vector<std::string>& panels) {
  std::vector<std::string> have = Panels(), want = panels;
  std::sort(have.begin(), have.end());
  std::sort(want.begin(), want.end());
  if (have != want) return false;
  size_t k = 0;
  for (Node& n : nodes_)
    if (n.IsLeaf()) n.panel = panels[k++];
  return true;
}

std::vector<float> TileLayout::Fractions() const {
  std::vector<float> f;
  for (const Node& n : nodes_)
    if (n.a >= 0) f.push_back(n.fraction);
  return f;
}

void TileLayout::SetFractions(const std::vector<float>& fractions) {
  size_t k = 0;
  for (Node& n : nodes_)
    if (n.a >= 0 && k < fractions.size()) n.fraction = std::clamp(fractions[k++], 0.02f, 0.98f);
}

TileLayout DefaultTileLayout() {
  TileLayout t;
  const int left = t.Split(true, 0.2f, t.Leaf("Project"),
                           t.Split(true, 0.62f, t.Leaf("Pipeline"), t.Leaf("Timing")));
  const int beside = t.Split(true, 0.5f, t.Leaf("Input frame"), t.Leaf("Painted buffers"));
  const int top = t.Split(false, 0.64f, t.Leaf("3D view"), beside);
  const int stages = t.Split(false, 0.2f, t.Leaf("Stage: depth and visibility"),
                             t.Split(false, 0.25f, t.Leaf("Stage: warp to buffer"),
                                     t.Split(false, 1.0f / 3, t.Leaf("Stage: background"),
                                             t.Split(false, 0.5f, t.Leaf("Stage: refine alignment"),
                                                     t.Leaf("Stage: paint")))));
  // The tools in the stage row's place, as tabs; they start closed, so the row shows.
  const int below = t.Tabs({{stages, "Stages"},
                            {t.Leaf("Poses"), ""},
                            {t.Leaf("Calibration"), ""},
                            {t.Leaf("New project"), ""}});
  const int centre = t.Split(true, 0.6f, top, below);
  t.SetToolFraction(centre, 0.42f);  // a tool gets more of the height than the stage row
  const int right = t.Split(true, 0.55f, t.Leaf("Grouping"), t.Leaf("Misalignment"));
  t.SetRoot(t.Split(false, 0.2f, left, t.Split(false, 0.78f, centre, right)));
  return t;
}

}  // namespace fresco
