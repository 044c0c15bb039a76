#include "calib/tag_corner_edges.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

namespace fresco::calib {
namespace {

constexpr double kFirst = 0.06, kLast = 0.4;  // the part of the edge used, from the corner
constexpr double kStepPx = 0.25;              // along the normal
constexpr double kMinContrastGrey = 20;       // an edge weaker than this is not trusted
constexpr int kMinPoints = 5;
constexpr double kNone = 1e9;  // no crossing
// The second sampling reaches this far to each side of the edge: past a 1 px blur's ramp.
constexpr double kPlateauPx = 3;
// The tag's border along an edge (the edge's length times its share of black bits: 1 of 8, or
// 2 of 10) as thick as this or more: the other edge's cuts across it reach the border's black.
// Thinner, a corner from the edges lies 0.1 px out of the tag (OpenCV's 1-bit border on a tag
// under 20 px: TagCornerEdgesTest's half-wide tags, 0.13 px); an edge that short whose levels
// fewer than kMinPoints cuts near the corner give is then not placed.
constexpr double kMinBorderPx = 2.5;

// Bilinear grey at (x, y); -1 outside the image.
double Grey(const cv::Mat& gray, double x, double y) {
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= gray.cols || y0 + 1 >= gray.rows) return -1;
  const double fx = x - x0, fy = y - y0;
  const uint8_t* r0 = gray.ptr<uint8_t>(y0);
  const uint8_t* r1 = gray.ptr<uint8_t>(y0 + 1);
  return (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) +
         fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
}

// The grey along `normal` through `base`, at offsets centre - half_px .. centre + half_px
// every kStepPx; false when it leaves the image.
bool Profile(const cv::Mat& gray, const Eigen::Vector2d& base, const Eigen::Vector2d& normal,
             double centre, double half_px, std::vector<double>* grey) {
  const int steps = static_cast<int>(std::lround(2 * half_px / kStepPx));
  grey->resize(steps + 1);
  for (int i = 0; i <= steps; ++i) {
    const Eigen::Vector2d q = base + (centre - half_px + i * kStepPx) * normal;
    (*grey)[i] = Grey(gray, q.x(), q.y());
    if ((*grey)[i] < 0) return false;
  }
  return true;
}

// Where `grey` (Profile's, half_px each side) crosses `level`, as an offset from its middle:
// the crossing nearest the middle; kNone when none.
double Crossing(const std::vector<double>& grey, double half_px, double level) {
  double best = kNone;
  for (size_t i = 0; i + 1 < grey.size(); ++i) {
    if ((grey[i] - level) * (grey[i + 1] - level) > 0 || grey[i] == grey[i + 1]) continue;
    const double at = -half_px + (i + (level - grey[i]) / (grey[i + 1] - grey[i])) * kStepPx;
    if (std::abs(at) < std::abs(best)) best = at;
  }
  return best;
}

// Where an edge lies across a cut, from the grey's area about its level crossing. A crossing
// of a sharp edge (its ramp about a pixel wide) interpolated bilinearly between pixels is
// pulled towards the pixels' centres: up to 0.13 px off with the edge's phase against the
// pixel grid, the same along a near-axis-aligned edge (0.07 px rms over the phases, box-filtered
// pixels). Area is what a pixel keeps of an edge whatever its phase: within kAreaHalfPx of the
// crossing (a sharp edge's ramp, a pixel, widened by the interpolation), the edge lies where a
// step has the area the grey (made linear) has. A blurred ramp reaches past the window on both
// sides alike, so the window cuts nothing from the answer near the crossing.
constexpr double kAreaHalfPx = 1.5;
constexpr int kAreaSteps = 30;
constexpr double kAreaStepPx = 2 * kAreaHalfPx / kAreaSteps;

// The grey made linear in the light: t (0: the edge's dark level, 1: its light level, clamped)
// to t^(1/g), where a power curve g puts a linear 0.5 at `level` (0.5^g = level); a table.
class Linear {
 public:
  explicit Linear(double level) {
    const double g = std::log(level) / std::log(0.5);
    for (int i = 0; i <= kSteps; ++i) table_[i] = std::pow(static_cast<double>(i) / kSteps, 1 / g);
  }
  double operator()(double t) const {
    const double x = std::clamp(t, 0.0, 1.0) * kSteps;
    const int i = std::min(static_cast<int>(x), kSteps - 1);
    return table_[i] + (x - i) * (table_[i + 1] - table_[i]);
  }

 private:
  static constexpr int kSteps = 256;
  std::array<double, kSteps + 1> table_;
};

// The edge's offset along `normal` from `base` near the crossing `at`: the crossing moved by
// the difference between a step there and the linear grey, integrated over the window; the
// grey made monotonic outwards from the crossing first (the tag's bits behind a thin border, a
// narrow margin's far edge do not count). kNone when the window leaves the image.
double AreaEdge(const cv::Mat& gray, const Eigen::Vector2d& base, const Eigen::Vector2d& normal,
                double at, bool light_last, double dark, double light, const Linear& linear) {
  constexpr int n = kAreaSteps, mid = n / 2;
  std::array<double, n + 1> v;  // light at the window's far end
  for (int i = 0; i <= n; ++i) {
    const double x = -kAreaHalfPx + i * kAreaStepPx;
    const Eigen::Vector2d q = base + (at + (light_last ? x : -x)) * normal;
    const double grey = Grey(gray, q.x(), q.y());
    if (grey < 0) return kNone;
    v[i] = linear((grey - dark) / (light - dark));
  }
  for (int i = mid - 1; i >= 0; --i) v[i] = std::min(v[i], v[i + 1]);
  for (int i = mid + 1; i <= n; ++i) v[i] = std::max(v[i], v[i - 1]);
  double moved = 0;  // trapezoids; the step is 0.5 at the crossing itself
  for (int i = 0; i <= n; ++i) {
    const double step = i < mid ? 0 : i == mid ? 0.5 : 1;
    moved += (i == 0 || i == n ? 0.5 : 1.0) * (step - v[i]) * kAreaStepPx;
  }
  return at + (light_last ? moved : -moved);
}

// The q-quantile of `values` (0 <= q <= 1); `values` is reordered.
double Quantile(std::vector<double>* values, double q) {
  const size_t k = static_cast<size_t>(q * (values->size() - 1));
  std::nth_element(values->begin(), values->begin() + k, values->end());
  return (*values)[k];
}

// The cuts across one edge of a tag (EdgeCutsOf) and the edge's levels.
struct EdgeCuts {
  struct Cut {
    Eigen::Vector2d base;
    double first = 0;  // the crossing, along `normal` from base
    bool light_last = true;  // the light side along `normal`
    std::vector<double> grey;
  };
  std::vector<Cut> cuts;
  Eigen::Vector2d from, along, normal;
  double half = 0;             // the second sampling's reach, each side
  double dark = 0, light = 0;  // the edge's levels
};

// The cuts across the edge from `from` to `to` and the edge's levels; false when too few cuts
// near `from` show an edge.
//
// Each cut across the edge is first placed where its grey crosses halfway between its own
// darkest and lightest samples, then sampled again centred there; the edge's levels are the
// darkest quarter of the inner ends and the lightest quarter of the outer ends of the cuts
// near `from` (kFirst..kLast of the edge, or the first kMinPoints cuts where fewer are there: a
// tag seen at a slant, its edge under 17.5 px, where its border is kMinBorderPx thick or more),
// kPlateauPx or more from the edge. A cut's own ends are not the levels on a small blurred
// tag: centred on a chord pulled into the tag, or reaching the tag's bits behind a thin border,
// the dark end is darker or lighter than the border's black and the halfway crossing moves
// (0.1-0.17 px into a 24-32 px tag blurred 1 px); the border's black shows where the bits
// behind it are black too. The cuts go on along
// the whole edge, as far from `to` as the first is from `from`: they give the edge's curve.
bool EdgeCutsOf(const cv::Mat& gray, const Eigen::Vector2d& from, const Eigen::Vector2d& to,
                int border_bits, EdgeCuts* edge) {
  const double length = (to - from).norm();
  if (length < 8) return false;
  const Eigen::Vector2d along = (to - from) / length, normal(-along.y(), along.x());
  const double reach = std::clamp(0.08 * length, 1.5, 4.0);
  const double half = std::max(reach, kPlateauPx);  // the second sampling, each side
  edge->from = from, edge->along = along, edge->normal = normal, edge->half = half;
  std::vector<EdgeCuts::Cut>& cuts = edge->cuts;
  cuts.clear();
  std::vector<double> dark_ends, light_ends, grey;
  const double first_t = std::max(kFirst, (reach + 1.5) / length);
  const bool border_holds = length * border_bits / (6 + 2 * border_bits) >= kMinBorderPx;
  const double last_t =
      border_holds ? std::max(kLast, first_t + (kMinPoints - 0.5) / length) : kLast;
  for (double t = first_t; t <= 1 - first_t; t += 1.0 / length) {
    EdgeCuts::Cut cut;
    cut.base = from + t * length * along;
    if (!Profile(gray, cut.base, normal, 0, reach, &grey)) continue;
    const double lo = *std::min_element(grey.begin(), grey.end());
    const double hi = *std::max_element(grey.begin(), grey.end());
    if (hi - lo < kMinContrastGrey) continue;
    cut.first = Crossing(grey, reach, 0.5 * (lo + hi));
    if (cut.first == kNone || !Profile(gray, cut.base, normal, cut.first, half, &cut.grey))
      continue;
    cut.light_last = grey.back() > grey.front();  // from the first, shorter cut
    if (t <= last_t) {
      const int n = static_cast<int>(cut.grey.size()), ends = std::max(1, n / 6);
      double a = 0, b = 0;
      for (int i = 0; i < ends; ++i) a += cut.grey[i], b += cut.grey[n - 1 - i];
      // A narrow light band (a paper margin under kPlateauPx before a dark surround): the
      // light end is dark again; its level is the band's lightest grey.
      const bool light_last = cut.light_last;
      double light_end = (light_last ? b : a) / ends;
      const auto half_begin = cut.grey.begin() + (light_last ? n / 2 : 0);
      const double band = *std::max_element(half_begin, half_begin + n / 2);
      if (band - light_end > kMinContrastGrey) light_end = band;
      dark_ends.push_back((light_last ? a : b) / ends);
      light_ends.push_back(light_end);
    }
    cuts.push_back(std::move(cut));
  }
  if (static_cast<int>(dark_ends.size()) < kMinPoints) return false;
  edge->dark = Quantile(&dark_ends, 0.25), edge->light = Quantile(&light_ends, 0.75);
  return edge->light - edge->dark >= kMinContrastGrey;
}

// The edge as a curve: its offset along `normal` from the straight line from `from` a quadratic
// in the distance along it, o(s) = c[0] + c[1] s + c[2] s^2, fitted to the cuts each placed
// where it crosses `level` (0: the edge's dark level, 1: its light level), then by the grey's
// area about there (AreaEdge); false when too few are. A lens bends the board's straight edges
// (barrel: a 50 px edge near the imager's corner bows 0.2-0.3 px); a straight line through the part
// near the corner, taken on to the corner, misses it by a tenth of that, and the misses follow the
// distortion (seed 3, 40 views: the lens solved 0.06 px RMS off from the true corners moved so).
bool EdgeCurve(const cv::Mat& gray, const EdgeCuts& edge, double level, Eigen::Vector3d* c) {
  std::vector<Eigen::Vector2d> points;  // (s, offset)
  const Linear linear(level);
  for (const EdgeCuts::Cut& cut : edge.cuts) {
    const double second =
        Crossing(cut.grey, edge.half, edge.dark + level * (edge.light - edge.dark));
    if (second == kNone) continue;
    const double at = AreaEdge(gray, cut.base, edge.normal, cut.first + second, cut.light_last,
                               edge.dark, edge.light, linear);
    if (at == kNone) continue;
    const Eigen::Vector2d q = cut.base + at * edge.normal - edge.from;
    points.emplace_back(q.dot(edge.along), q.dot(edge.normal));
  }
  if (static_cast<int>(points.size()) < kMinPoints) return false;
  const double scale = points.back().x();  // s scaled to about 1: a well conditioned fit
  Eigen::MatrixXd a(points.size(), 3);
  Eigen::VectorXd b(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const double u = points[i].x() / scale;
    a.row(i) << 1, u, u * u;
    b(i) = points[i].y();
  }
  const Eigen::Vector3d fit = a.colPivHouseholderQr().solve(b);
  *c = Eigen::Vector3d(fit(0), fit(1) / scale, fit(2) / (scale * scale));
  return true;
}

}  // namespace

bool CrossingSquareAt(const cv::Mat& gray, const std::array<Eigen::Vector2d, 4>& p, int k) {
  const Eigen::Vector2d centre = 0.25 * (p[0] + p[1] + p[2] + p[3]);
  const Eigen::Vector2d outward = p[k] - centre;  // half a diagonal
  // Kalibr's square spans the 0.3 tag edges of gap beyond the corner: 0.15 of the half
  // diagonal out is in it (0.11 edges each way); the tag's black as far in; the gap's white
  // 0.12 edges out from the middle of the tag's edge through the corner.
  const Eigen::Vector2d square = p[k] + 0.15 * outward;
  const Eigen::Vector2d black = p[k] - 0.15 * outward;
  const Eigen::Vector2d middle = 0.5 * (p[k] + p[(k + 1) % 4]);
  const Eigen::Vector2d beside =
      middle + 0.12 * (p[k] - p[(k + 1) % 4]).norm() * (middle - centre).normalized();
  // Kalibr's square has the gaps' white on both its sides: halfway across each gap, 0.15 tag
  // edges along the tag's edge from the corner. Beyond a narrow paper margin (under 0.15 tag
  // edges) on a dark surround one of them is dark, and so is the diagonal: no square there.
  const Eigen::Vector2d a = p[(k + 1) % 4] - p[k], b = p[(k + 3) % 4] - p[k];
  const Eigen::Vector2d gap_a = p[k] + 0.15 * (a - b), gap_b = p[k] + 0.15 * (b - a);
  const double g = Grey(gray, square.x(), square.y()), dark = Grey(gray, black.x(), black.y());
  const double light = Grey(gray, beside.x(), beside.y());
  const double ga = Grey(gray, gap_a.x(), gap_a.y()), gb = Grey(gray, gap_b.x(), gap_b.y());
  if (g < 0 || dark < 0 || light < 0 || ga < 0 || gb < 0)
    return true;  // cannot tell: keep the saddle refinement
  const double white = std::max({light, ga, gb});
  const auto nearer_dark = [&](double v) { return std::abs(v - dark) < std::abs(v - white); };
  return nearer_dark(g) && !nearer_dark(ga) && !nearer_dark(gb);
}

bool CornerFromEdges(const cv::Mat& gray, const std::array<Eigen::Vector2d, 4>& p, int k,
                     Eigen::Vector2d* corner, bool* left_out, std::array<double, 2>* levels,
                     double level, int border_bits) {
  if (left_out != nullptr) *left_out = false;
  EdgeCuts cuts_a, cuts_b;
  if (!EdgeCutsOf(gray, p[k], p[(k + 1) % 4], border_bits, &cuts_a) ||
      !EdgeCutsOf(gray, p[k], p[(k + 3) % 4], border_bits, &cuts_b))
    return false;
  // The two edges' light levels differ: beside the lighter one is the gap's white, beside the
  // other a paper margin of a few pixels blurred onto a dark surround, whose white is never
  // reached; no level places that edge (0.10-0.18 px into the tag whichever is taken, the
  // other edge's included: calib_detect_elsewhere --margin 0.1 --gamma 2 --solve, dark,
  // blurred). Such a corner is left out.
  const double lighter = std::max(cuts_a.light, cuts_b.light);
  const double darker_light = std::min(cuts_a.light, cuts_b.light);
  const double dark = std::min(cuts_a.dark, cuts_b.dark);
  if (levels != nullptr) *levels = {dark, lighter};
  if (lighter - darker_light > kMaxEdgeLightDeficit * (lighter - dark)) {
    if (left_out != nullptr) *left_out = true;
    return false;
  }
  Eigen::Vector3d ca, cb;
  if (!EdgeCurve(gray, cuts_a, level, &ca) || !EdgeCurve(gray, cuts_b, level, &cb)) return false;
  // Where the two curves meet: each replaced by its tangent where the other's meeting point
  // lies along it, from the tangents at `from`; the meeting point settles in a few rounds.
  Eigen::Vector2d meet = p[k];
  for (int round = 0; round < 4; ++round) {
    const auto tangent = [&](const EdgeCuts& e, const Eigen::Vector3d& c, Eigen::Vector2d* point,
                             Eigen::Vector2d* direction) {
      const double s = (meet - e.from).dot(e.along);
      *point = e.from + s * e.along + (c(0) + c(1) * s + c(2) * s * s) * e.normal;
      *direction = (e.along + (c(1) + 2 * c(2) * s) * e.normal).normalized();
    };
    Eigen::Vector2d a, da, b, db;
    tangent(cuts_a, ca, &a, &da), tangent(cuts_b, cb, &b, &db);
    // a + s da = b + u db
    Eigen::Matrix2d m;
    m << da, -db;
    if (std::abs(m.determinant()) < 0.2) return false;  // nearly parallel
    const Eigen::Vector2d s = m.colPivHouseholderQr().solve(b - a);
    meet = a + s(0) * da;
  }
  const double edge = std::min((p[(k + 1) % 4] - p[k]).norm(), (p[(k + 3) % 4] - p[k]).norm());
  if ((meet - p[k]).norm() > std::max(1.5, 0.05 * edge)) return false;
  *corner = meet;
  return true;
}

}  // namespace fresco::calib
