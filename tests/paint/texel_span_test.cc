#include "pipeline/paint/texel_span.h"

#include <random>

#include <gtest/gtest.h>

namespace fresco {
namespace {

// Every centre of row j in [i0, i1] tested against the three edges, as texels were placed
// before the spans.
bool InsideAllEdges(const Eigen::Vector2d q[3], double sign, int i, int j) {
  const Eigen::Vector2d c(i + 0.5, j + 0.5);
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector2d e = q[(k + 1) % 3] - q[k], r = c - q[k];
    if (!(sign * (e.x() * r.y() - e.y() * r.x()) >= 0)) return false;
  }
  return true;
}

TEST(TexelSpan, EachRowsSpanHoldsExactlyTheCentresTheEdgeTestsPutInside) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  long long rows = 0, inside = 0;
  for (int t = 0; t < 20000; ++t) {
    // Triangles from slivers to a few hundred texels, corners on texel centres, on centre
    // rows and columns (edges through centres, horizontal and vertical edges) or anywhere.
    const double size = std::pow(10.0, -1.0 + 3.5 * unit(rng));
    const Eigen::Vector2d base(500 * unit(rng), 500 * unit(rng));
    Eigen::Vector2d q[3];
    for (int k = 0; k < 3; ++k) {
      q[k] = base + size * Eigen::Vector2d(unit(rng), unit(rng));
      if (t % 4 == 1) q[k] = (q[k].array() - 0.5).round() + 0.5;
      if (t % 4 == 2 && k == 2) q[2].y() = q[1].y();
      if (t % 4 == 3 && k == 2) q[2].x() = q[0].x() + 1e-12 * unit(rng);
    }
    const double area2 =
        (q[1] - q[0]).x() * (q[2] - q[0]).y() - (q[1] - q[0]).y() * (q[2] - q[0]).x();
    if (area2 == 0) continue;
    const double sign = area2 > 0 ? 1.0 : -1.0;
    const int i0 = static_cast<int>(std::floor(std::min({q[0].x(), q[1].x(), q[2].x()}) - 0.5));
    const int i1 = static_cast<int>(std::ceil(std::max({q[0].x(), q[1].x(), q[2].x()}) - 0.5));
    const int j0 = static_cast<int>(std::floor(std::min({q[0].y(), q[1].y(), q[2].y()}) - 0.5));
    const int j1 = static_cast<int>(std::ceil(std::max({q[0].y(), q[1].y(), q[2].y()}) - 0.5));
    for (int j = j0; j <= j1; ++j) {
      // Also rows cut short, as at a buffer's border.
      const int from = t % 3 == 0 ? i0 + (i1 - i0) / 3 : i0;
      int lo = 0, hi = -1;
      CentresInsideRow(q, sign, j, from, i1, &lo, &hi);
      ++rows;
      for (int i = from; i <= i1; ++i) {
        const bool expected = InsideAllEdges(q, sign, i, j);
        inside += expected;
        ASSERT_EQ(lo <= i && i <= hi, expected) << "triangle " << t << " row " << j << " texel "
                                                << i << " span [" << lo << ", " << hi << "]";
      }
    }
  }
  EXPECT_GT(rows, 100000);
  EXPECT_GT(inside, 1000000);
}

}  // namespace
}  // namespace fresco
