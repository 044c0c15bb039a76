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

bool TileLayout::AnyOpen(int node, const std::function<bool(const std::string&)>& is_open) const {
  const Node& n = nodes_[node];
  if (n.a < 0) return is_open(n.panel);
  return AnyOpen(n.a, is_open) || AnyOpen(n.b, is_open);
}

void TileLayout::Place(int node, const LayoutRect& rect, float gap_px,
                       const std::function<bool(const std::string&)>& is_open,
                       std::vector<Tile>* tiles, std::vector<Splitter>* splitters) const {
  const Node& n = nodes_[node];
  if (n.a < 0) {
    tiles->push_back({n.panel, rect});
    return;
  }
  const bool a_open = AnyOpen(n.a, is_open), b_open = AnyOpen(n.b, is_open);
  if (!a_open || !b_open) {  // one side closed: the other takes the whole rectangle
    if (a_open) Place(n.a, rect, gap_px, is_open, tiles, splitters);
    if (b_open) Place(n.b, rect, gap_px, is_open, tiles, splitters);
    return;
  }
  const float extent = n.stacked ? rect.h : rect.w;
  const float first = std::max(0.0f, std::round(n.fraction * extent - 0.5f * gap_px));
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
  splitters->push_back({node, n.stacked, bar, extent});
  Place(n.a, ra, gap_px, is_open, tiles, splitters);
  Place(n.b, rb, gap_px, is_open, tiles, splitters);
}

void TileLayout::Compute(const LayoutRect& band, float gap_px,
                         const std::function<bool(const std::string&)>& is_open,
                         std::vector<Tile>* tiles, std::vector<Splitter>* splitters) const {
  tiles->clear();
  splitters->clear();
  if (!maximised_.empty() && is_open(maximised_)) {
    tiles->push_back({maximised_, band});
    return;
  }
  if (root_ >= 0 && AnyOpen(root_, is_open)) Place(root_, band, gap_px, is_open, tiles, splitters);
}

void TileLayout::Drag(const Splitter& splitter, float delta_px, float min_px) {
  if (splitter.node < 0 || splitter.node >= static_cast<int>(nodes_.size())) return;
  if (splitter.extent <= 0) return;
  Node& n = nodes_[splitter.node];
  const float lo = std::min(0.5f, min_px / splitter.extent);
  n.fraction = std::clamp(n.fraction + delta_px / splitter.extent, lo, 1.0f - lo);
}

bool TileLayout::Contains(const std::string& title) const {
  for (const Node& n : nodes_)
    if (n.a < 0 && n.panel == title) return true;
  return false;
}

void TileLayout::ToggleMaximised(const std::string& title) {
  maximised_ = maximised_ == title ? "" : title;
}

bool TileLayout::Swap(const std::string& a, const std::string& b) {
  Node* na = nullptr;
  Node* nb = nullptr;
  for (Node& n : nodes_) {
    if (n.a >= 0) continue;
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
    if (n.a < 0) panels.push_back(n.panel);
  return panels;
}

bool TileLayout::SetPanels(const std::vector<std::string>& panels) {
  std::vector<std::string> have = Panels(), want = panels;
  std::sort(have.begin(), have.end());
  std::sort(want.begin(), want.end());
  if (have != want) return false;
  size_t k = 0;
  for (Node& n : nodes_)
    if (n.a < 0) n.panel = panels[k++];
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
  const int centre = t.Split(true, 0.6f, top, stages);
  const int right = t.Split(true, 0.55f, t.Leaf("Grouping"), t.Leaf("Misalignment"));
  t.SetRoot(t.Split(false, 0.2f, left, t.Split(false, 0.78f, centre, right)));
  return t;
}

}  // namespace fresco
