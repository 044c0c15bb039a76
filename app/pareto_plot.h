// The speed/accuracy picture of `fresco bench`: one point per run (fps across, PSNR up),
// the Pareto front (no other run both faster and more accurate) drawn as a red line.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace fresco {

struct ParetoPoint {
  double fps = 0;
  double psnr_db = 0;
  std::string label;  // the settings that differ from the defaults
};

// Indices of the points on the front (maximising both), by increasing fps.
std::vector<size_t> ParetoFront(const std::vector<ParetoPoint>& points);

// A BGR picture (about 1000x640) with axes, every point labelled and the front marked.
cv::Mat DrawPareto(const std::vector<ParetoPoint>& points, const std::string& title);

}  // namespace fresco
