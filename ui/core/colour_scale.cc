#include "ui/core/colour_scale.h"

#include <opencv2/imgproc.hpp>

namespace fresco {
namespace {

bool StartsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

}  // namespace

ColourScale DifferenceHeatScale() {
  return {cv::COLORMAP_INFERNO, "0", "64+ grey levels |difference|"};
}

bool FalseColourScaleOf(const std::string& stage, const std::string& image, ColourScale* scale) {
  if (stage == "depth" && image == "depth") {  // nearest surface bright, scaled per frame
    *scale = {cv::COLORMAP_VIRIDIS, "far", "near"};
    return true;
  }
  if (stage == "refine" &&
      (StartsWith(image, "residual_before") || StartsWith(image, "residual_after"))) {
    *scale = DifferenceHeatScale();
    return true;
  }
  return false;
}

}  // namespace fresco
