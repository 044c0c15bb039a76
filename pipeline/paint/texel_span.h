// Which texel centres of a row a triangle covers, in texel coordinates (texel (i, j)'s centre
// at (i + 0.5, j + 0.5)): the same texels as testing every centre of the row against the three
// edges, found by testing a few.
#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

namespace fresco {

// Whether texel (i, j)'s centre lies on the inner side of edge k (q[k] to q[k+1]) of the
// triangle q whose texel-coordinate area has sign `sign` (+1 or -1), or on the edge.
inline bool CentreInsideEdge(const Eigen::Vector2d q[3], double sign, int k, int i, int j) {
  const Eigen::Vector2d c(i + 0.5, j + 0.5);
  const Eigen::Vector2d e = q[(k + 1) % 3] - q[k], r = c - q[k];
  return sign * (e.x() * r.y() - e.y() * r.x()) >= 0;
}

// The texels [*lo, *hi] of row j, within [i0, i1], whose centres CentreInsideEdge puts inside
// all three edges (*lo > *hi: none). Along a row each edge's test is monotone in i (its
// arithmetic is a chain of monotone roundings), so the texels inside an edge are a prefix or a
// suffix of the row: its end is guessed from the edge's line and moved until the test itself
// says it is the end.
inline void CentresInsideRow(const Eigen::Vector2d q[3], double sign, int j, int i0, int i1,
                             int* lo, int* hi) {
  *lo = i0;
  *hi = i1;
  for (int k = 0; k < 3 && *lo <= *hi; ++k) {
    const Eigen::Vector2d e = q[(k + 1) % 3] - q[k];
    const double slope = -sign * e.y();  // of the test's value as i grows
    if (slope == 0) {
      if (!CentreInsideEdge(q, sign, k, i0, j)) *hi = *lo - 1;
      continue;
    }
    // Where the edge's line crosses the row, as a texel index.
    const double cross = q[k].x() + e.x() * ((j + 0.5) - q[k].y()) / e.y() - 0.5;
    const double guess = std::isnan(cross) ? i0 : std::clamp(cross, i0 - 1.0, i1 + 1.0);
    if (slope > 0) {  // inside from some i on
      int g = static_cast<int>(std::ceil(guess));
      while (g > i0 && CentreInsideEdge(q, sign, k, g - 1, j)) --g;
      while (g <= i1 && !CentreInsideEdge(q, sign, k, g, j)) ++g;
      *lo = std::max(*lo, g);
    } else {  // inside up to some i
      int g = static_cast<int>(std::floor(guess));
      while (g < i1 && CentreInsideEdge(q, sign, k, g + 1, j)) ++g;
      while (g >= i0 && !CentreInsideEdge(q, sign, k, g, j)) --g;
      *hi = std::min(*hi, g);
    }
  }
}

}  // namespace fresco
