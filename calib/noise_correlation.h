// AprilTag corners are not independent: the four corners of one tag come from one quad fit,
// so they share part of their error (mrcal's docs warn about this for AprilTag boards). We
// measure that correlation from a solve's residuals and inflate every propagated uncertainty
// by the design effect of m = 4 equally correlated samples, sqrt(1 + (m - 1) rho).
#pragma once

#include <vector>

#include "calib/mrcal_solve.h"
#include "calib/observations.h"

namespace fresco::calib {

// Correlation rho of the residuals of different corners of the same tag (same coordinate),
// over the inlier corners of `fit` (corner id / 4 is the tag). 0 without pairs.
double TagCornerCorrelation(const std::vector<BoardView>& views, const SolveResult& fit);

// sqrt(1 + 3 rho), at least 1 (negative correlation is not credited).
double TagNoiseInflation(double rho);

}  // namespace fresco::calib
