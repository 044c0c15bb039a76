#include "calib/tag_dilation.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <Eigen/Dense>

namespace fresco::calib {
namespace {

// Corner positions by id, and whether each came from the edges.
struct Lookup {
  std::map<int, size_t> index;
  const std::vector<CornerObservation>* corners;
  const std::vector<bool>* from_edges;
  const Eigen::Vector2d* At(int id) const {
    const auto it = index.find(id);
    return it == index.end() ? nullptr : &(*corners)[it->second].pixel;
  }
  bool Edged(int id) const {
    const auto it = index.find(id);
    return it != index.end() && (*from_edges)[it->second];
  }
};

Lookup MakeLookup(const std::vector<CornerObservation>& corners,
                  const std::vector<bool>& from_edges) {
  Lookup l{{}, &corners, &from_edges};
  for (size_t i = 0; i < corners.size(); ++i) l.index[corners[i].id] = i;
  return l;
}

// The normal shift of the edges crossing the line of a, b (tag A's two corners) and c, d
// (tag B's), B next to A on the board `spacing` tag edges away, `crossing` the direction of
// A's edge through b: the shift that restores the cross ratio of the four points on the board.
// NaN when the four are not in order along the line.
double ShiftFromPair(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                     const Eigen::Vector2d& d, const Eigen::Vector2d& crossing, double spacing) {
  const Eigen::Vector2d line = (d - a).normalized();
  const double m2 = line.dot(b - a), m3 = line.dot(c - a), m4 = line.dot(d - a);
  if (!(0 < m2 && m2 < m3 && m3 < m4)) return NAN;
  const double ratio = (1 + spacing) * (1 + spacing) / (spacing * (2 + spacing));
  // Corrected positions a + s, b - s, c + s, d - s keep (c - a) and (d - b); their cross
  // ratio (c - a)(d - b) / ((c - b)(d - a)) is the board's when (G + 2s)(L - 2s) = K.
  const double gap = m3 - m2, span = m4, k = m3 * (m4 - m2) / ratio;
  const double disc = (span - gap) * (span - gap) + 4 * (gap * span - k);
  if (disc < 0) return NAN;
  const double shift_on_line = 0.25 * ((span - gap) - std::sqrt(disc));
  const Eigen::Vector2d e = crossing.normalized();
  return shift_on_line * std::abs(line.x() * e.y() - line.y() * e.x());
}

}  // namespace

double TagEdgeShift_px(const BoardSpec& spec, const std::vector<CornerObservation>& corners,
                       const std::vector<bool>& from_edges, int min_pairs) {
  const Lookup l = MakeLookup(corners, from_edges);
  std::vector<double> shifts;
  // (A's two corners, B's two, A's corner towards which the crossing edge runs from A's second)
  const auto pair = [&](int ta, int tb, int ka, int kb, int k_cross) {
    const int ids[4] = {4 * ta + ka, 4 * ta + kb, 4 * tb + ka, 4 * tb + kb};
    for (int id : ids)
      if (!l.Edged(id)) return;
    const Eigen::Vector2d* cross = l.At(4 * ta + k_cross);
    if (cross == nullptr) return;
    const double s = ShiftFromPair(*l.At(ids[0]), *l.At(ids[1]), *l.At(ids[2]), *l.At(ids[3]),
                                   *cross - *l.At(ids[1]), spec.spacing);
    if (std::isfinite(s)) shifts.push_back(s);
  };
  for (int t = 0; t < spec.cols * spec.rows; ++t) {
    if (t % spec.cols + 1 < spec.cols) {  // B to the right of A
      pair(t, t + 1, 0, 1, 2);
      pair(t, t + 1, 3, 2, 1);
    }
    if (t / spec.cols + 1 < spec.rows) {  // B above A
      pair(t, t + spec.cols, 0, 3, 2);
      pair(t, t + spec.cols, 1, 2, 3);
    }
  }
  if (static_cast<int>(shifts.size()) < min_pairs) return 0;
  std::nth_element(shifts.begin(), shifts.begin() + shifts.size() / 2, shifts.end());
  return shifts[shifts.size() / 2];
}

void ShiftTagEdges(double shift_px, const std::vector<bool>& from_edges,
                   std::vector<CornerObservation>* corners,
                   const std::map<int, TagQuad>* outlines) {
  if (shift_px == 0) return;
  const std::vector<CornerObservation> before = *corners;
  const Lookup l = MakeLookup(before, from_edges);
  for (size_t i = 0; i < before.size(); ++i) {
    if (!from_edges[i]) continue;
    const int tag = before[i].id / 4, k = before[i].id % 4;
    const Eigen::Vector2d* next = l.At(4 * tag + (k + 1) % 4);
    const Eigen::Vector2d* prev = l.At(4 * tag + (k + 3) % 4);
    const Eigen::Vector2d c = before[i].pixel;
    Eigen::Vector2d d1, d2;
    if (next != nullptr && prev != nullptr) {
      d1 = (*next - c).normalized(), d2 = (*prev - c).normalized();
    } else {
      // A neighbour left out: the directions of the outline as read (1-2 px off over an edge
      // of 20 px or more: the shift, under 1 px, moves a few hundredths of a pixel less
      // or more). Before, such corners kept the whole shift (the inner corners of the outer
      // tags beside a narrow margin on a dark surround: 0.07-0.15 px out of the tag).
      if (outlines == nullptr) continue;
      const auto it = outlines->find(tag);
      if (it == outlines->end()) continue;
      const std::array<Eigen::Vector2d, 4>& q = it->second.p;
      d1 = (q[(k + 1) % 4] - q[k]).normalized(), d2 = (q[(k + 3) % 4] - q[k]).normalized();
    }
    Eigen::Vector2d n1(-d1.y(), d1.x()), n2(-d2.y(), d2.x());  // into the tag
    if (n1.dot(d2) < 0) n1 = -n1;
    if (n2.dot(d1) < 0) n2 = -n2;
    Eigen::Matrix2d m;
    m << n1.transpose(), n2.transpose();
    if (std::abs(m.determinant()) < 0.2) continue;
    // The edges moved outwards by shift_px: back inwards by as much.
    (*corners)[i].pixel = c + m.inverse() * Eigen::Vector2d(shift_px, shift_px);
  }
}

}  // namespace fresco::calib
