// Paint stage (paper eq. 4 and §4's update policy): writes a frame's warped samples into a
// base buffer's persistent texels. Buffers are fixed-size: memory does not grow with the
// video's length.
#pragma once

#include <opencv2/core.hpp>

#include "pipeline/core/project.h"
#include "pipeline/paint/base_buffer.h"
#include "pipeline/paint/frame_warp.h"
#include "pipeline/paint/texel_update.h"

namespace fresco {

void InitPaintedBuffer(const BaseBuffer& buffer, PaintedBuffer* painted);

// `mask` (CV_8U, optional): texels to leave alone (e.g. foreground) where non-zero.
PaintUpdateStats PaintBuffer(const BaseBuffer& buffer, const WarpedBuffer& warped,
                             const cv::Mat& mask, const PipelineOptions& options,
                             PaintedBuffer* painted);

}  // namespace fresco
