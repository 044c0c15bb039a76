// Pictures for the operator (OpenCV drawing, PNG):
// - residuals: per-image RMS bars (outlier counts in red) above the residual vectors of
//   every corner drawn on the imager, magnified;
// - coverage: every observed corner on the imager, coloured by image, outliers as red
//   crosses, over the 16 x 12 cells the coverage figure counts (empty cells shaded).
#pragma once

#include <opencv2/core.hpp>

#include "calib/calibrate.h"

namespace fresco::calib {

cv::Mat DrawResiduals(const CalibrationRun& run);
cv::Mat DrawCoverage(const CalibrationRun& run);  // before the solve too (no outliers then)
// Projection uncertainty over the imager at the boards' range (run.uncertainty): a heat map
// with labelled contours, the observed corners as dots, the figures and a colour bar.
// Empty when no map was computed.
cv::Mat DrawUncertainty(const CalibrationRun& run);
// One image with its detected corners (first corner red, detection order joined; outliers
// of `fit` as red crosses when given) and the corner count / RMS.
cv::Mat DrawDetections(const cv::Mat& image, const std::vector<CornerObservation>& corners,
                       const ViewFit* fit = nullptr);

}  // namespace fresco::calib
