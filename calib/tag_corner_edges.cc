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

// The edge from `from` towards `to` near `from`, as a point on it and its direction; false
// when too few points show an edge.
bool EdgeLine(const cv::Mat& gray, const Eigen::Vector2d& from, const Eigen::Vector2d& to,
              Eigen::Vector2d* point, Eigen::Vector2d* direction) {
  const double length = (to - from).norm();
  if (length < 8) return false;
  const Eigen::Vector2d along = (to - from) / length, normal(-along.y(), along.x());
  const double reach = std::clamp(0.08 * length, 1.5, 4.0);
  const int steps = static_cast<int>(2 * reach / kStepPx);
  std::vector<Eigen::Vector2d> points;
  std::vector<double> profile(steps + 1);
  for (double t = std::max(kFirst, (reach + 1.5) / length); t <= kLast; t += 1.0 / length) {
    const Eigen::Vector2d base = from + t * length * along;
    bool inside = true;
    for (int i = 0; i <= steps && inside; ++i) {
      const Eigen::Vector2d q = base + (-reach + i * kStepPx) * normal;
      profile[i] = Grey(gray, q.x(), q.y());
      inside = profile[i] >= 0;
    }
    if (!inside) continue;
    // Where the grey crosses halfway between the profile's dark and light ends (unbiased for a
    // symmetric blur), the crossing nearest the chord.
    const double lo = *std::min_element(profile.begin(), profile.end());
    const double hi = *std::max_element(profile.begin(), profile.end());
    if (hi - lo < kMinContrastGrey) continue;
    const double half = 0.5 * (lo + hi);
    double best = -1, best_off = 1e9;
    for (int i = 0; i < steps; ++i) {
      if ((profile[i] - half) * (profile[i + 1] - half) > 0 || profile[i] == profile[i + 1])
        continue;
      const double at = i + (half - profile[i]) / (profile[i + 1] - profile[i]);
      const double off = std::abs(-reach + at * kStepPx);
      if (off < best_off) best_off = off, best = at;
    }
    if (best < 0) continue;
    points.push_back(base + (-reach + best * kStepPx) * normal);
  }
  if (static_cast<int>(points.size()) < kMinPoints) return false;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& q : points) mean += q;
  mean /= points.size();
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector2d& q : points) scatter += (q - mean) * (q - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(scatter);
  *point = mean;
  *direction = eigen.eigenvectors().col(1);  // the largest eigenvalue: along the line
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
  const double g = Grey(gray, square.x(), square.y()), dark = Grey(gray, black.x(), black.y());
  const double light = Grey(gray, beside.x(), beside.y());
  if (g < 0 || dark < 0 || light < 0) return true;  // cannot tell: keep the saddle refinement
  return std::abs(g - dark) < std::abs(g - light);
}

bool CornerFromEdges(const cv::Mat& gray, const std::array<Eigen::Vector2d, 4>& p, int k,
                     Eigen::Vector2d* corner) {
  Eigen::Vector2d a, da, b, db;
  if (!EdgeLine(gray, p[k], p[(k + 1) % 4], &a, &da) ||
      !EdgeLine(gray, p[k], p[(k + 3) % 4], &b, &db))
    return false;
  // a + s da = b + u db
  Eigen::Matrix2d m;
  m << da, -db;
  if (std::abs(m.determinant()) < 0.2) return false;  // nearly parallel
  const Eigen::Vector2d s = m.colPivHouseholderQr().solve(b - a);
  const Eigen::Vector2d meet = a + s(0) * da;
  const double edge = std::min((p[(k + 1) % 4] - p[k]).norm(), (p[(k + 3) % 4] - p[k]).norm());
  if ((meet - p[k]).norm() > std::max(1.5, 0.05 * edge)) return false;
  *corner = meet;
  return true;
}

}  // namespace fresco::calib
