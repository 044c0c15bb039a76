#include "calib/noise_correlation.h"

#include <algorithm>
#include <cmath>

namespace fresco::calib {

double TagCornerCorrelation(const std::vector<BoardView>& views, const SolveResult& fit) {
  double sum_products = 0, sum_squares = 0;
  long pairs = 0, singles = 0;
  for (size_t v = 0; v < views.size() && v < fit.views.size(); ++v) {
    const auto& corners = views[v].corners;
    for (size_t a = 0; a < corners.size(); ++a) {
      if (fit.views[v].outlier[a]) continue;
      sum_squares += fit.views[v].residual_px[a].squaredNorm();
      singles += 2;
      for (size_t b = a + 1; b < corners.size() && corners[b].id / 4 == corners[a].id / 4; ++b) {
        if (fit.views[v].outlier[b]) continue;
        sum_products += fit.views[v].residual_px[a].dot(fit.views[v].residual_px[b]);
        pairs += 2;
      }
    }
  }
  if (pairs == 0 || sum_squares <= 0) return 0;
  return (sum_products / pairs) / (sum_squares / singles);
}

double TagNoiseInflation(double rho) { return std::sqrt(std::max(1.0, 1 + 3 * rho)); }

}  // namespace fresco::calib
