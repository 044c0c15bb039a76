// Which debug images are false-coloured and what their colours mean, for the legend under
// them. Pure logic, no ImGui.
#pragma once

#include <string>

namespace fresco {

struct ColourScale {
  int colormap = 0;       // cv::COLORMAP_* the image was made with
  std::string low, high;  // what the two ends of the scale mean
};

// The scale of stage `stage`'s debug image `image` ("depth", "residual_before_b3", ...);
// false for images in their own colours (frames, buffers, masks).
bool FalseColourScaleOf(const std::string& stage, const std::string& image, ColourScale* scale);

// The misalignment review's difference heat map (|frame - painted model| in grey levels).
ColourScale DifferenceHeatScale();

}  // namespace fresco
