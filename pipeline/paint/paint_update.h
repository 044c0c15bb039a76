// Paint stage (paper eq. 4 and §4's update policy): writes a frame's warped samples into a
// base buffer's persistent texels. Buffers are fixed-size: memory does not grow with the
// video's length.
#pragma once

#include <opencv2/core.hpp>

#include "pipeline/core/project.h"
#include "pipeline/paint/base_buffer.h"
#include "pipeline/paint/frame_warp.h"

namespace fresco {

struct PaintedBuffer {
  cv::Mat bgra;     // CV_8UC4, alpha 255 where painted, 0 where never painted
  cv::Mat quality;  // CV_32F, quality of the stored sample (pixels per texel)
  int painted_surface_texels = 0;  // on-surface texels painted at least once
};

void InitPaintedBuffer(const BaseBuffer& buffer, PaintedBuffer* painted);

struct PaintUpdateStats {
  int written = 0;   // texels written this frame
  int rejected = 0;  // visible but kept the stored, sharper sample
  // Misalignment signal: over texels that were already painted and are seen again, the sum
  // of |grey(new sample) - grey(stored)| (0..255 each) and how many there were.
  double abs_grey_difference_sum = 0;
  int compared = 0;
};

// `mask` (CV_8U, optional): texels to leave alone (e.g. foreground) where non-zero.
PaintUpdateStats PaintBuffer(const BaseBuffer& buffer, const WarpedBuffer& warped,
                             const cv::Mat& mask, const PipelineOptions& options,
                             PaintedBuffer* painted);

}  // namespace fresco
