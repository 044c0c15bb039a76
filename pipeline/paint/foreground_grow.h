// Foreground grown by colour (background stage, before the mask is cleaned): a mover that
// covers some texels for as long as not is learned there as background, or left undecided,
// and only the texels that saw the background long enough flag it. Its samples elsewhere in
// the frame look like those the model did flag: the flag spreads from each flagged texel to
// neighbouring sampled texels whose colour is within `levels` of the flagged texel's (every
// channel), up to `reach` texels away. Evidence beyond one texel's history: the mover's
// extent in the frame.
#pragma once

#include <opencv2/core.hpp>

namespace fresco {

// `foreground`: CV_8U, non-zero = flagged, grown in place (255); `bgr` (CV_8UC3) and `valid`
// (CV_8U) the warped samples, all the same size (e.g. views of one region). Returns how many
// texels were added.
int GrowForegroundByColour(const cv::Mat& bgr, const cv::Mat& valid, int levels, int reach,
                           cv::Mat* foreground);

}  // namespace fresco
