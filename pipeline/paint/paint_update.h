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
// `warming` (CV_8U, optional): texels whose sample this frame is provisional (the background
// model is still warming up there). Those texels are then marked provisional, whether this
// sample was kept or not: their stored quality is negated (the magnitude kept). A stored
// sample that is provisional gives way to any trusted sample, and to a provisional one only
// by the update rule's quality test, so that while a model warms up the sharper samples are
// the ones shown, and the first trusted sample replaces them.
PaintUpdateStats PaintBuffer(const BaseBuffer& buffer, const WarpedBuffer& warped,
                             const cv::Mat& mask, const PipelineOptions& options,
                             PaintedBuffer* painted, const cv::Mat& warming = cv::Mat(),
                             bool held_out = false);

}  // namespace fresco
