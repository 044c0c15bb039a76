// Local seam levelling (pipeline.select.level_seams; in the select stage, after it has
// decided which texels keep their stored sample): where the frame's new samples meet texels
// that keep what the buffers hold, the painting would pass from one photo to another with a
// step in colour (light that changes across a photo: vignetting, haze, flare, which one gain
// per frame leaves). The frame's samples of the kept texels are compared with the stored ones
// cell by cell (cells of `cell_texels` texels of the buffer's rectangle; per channel the
// median log ratio), the cells without kept texels take their neighbours' correction, and every new
// sample is multiplied by the field interpolated between the cells' centres, scaled down with the
// texel's distance from the nearest kept texel (to none at `fade_texels`). Near a seam the new
// samples continue the colours that stay; away from it (a region the frame paints whole, or paints
// first) they keep their own, so corrections chain from frame to frame only as far as the fade
// reaches. Streaming, like the rest of the painting: each frame against the buffers as they are, no
// global solve at the end.
#pragma once

#include <opencv2/core.hpp>

#include "pipeline/paint/frame_warp.h"
#include "pipeline/paint/paint_update.h"

namespace fresco {

struct SeamLevelOptions {
  int cell_texels = 16;        // the correction's cells, texels a side
  int min_samples = 32;        // kept texels that make a cell measured
  double max_log_ratio = 0.5;  // texels whose ratio is further from 1 (movers) are left out
  int fill_cells = 4;          // cells without kept texels take their neighbours' correction
  int fade_texels = 16;        // the correction fades out over this distance from kept texels
};

struct SeamLevelStats {
  int cells_measured = 0;  // cells with enough kept texels
  int cells_filled = 0;    // cells corrected from their neighbours
  double abs_log_sum = 0;  // sum over measured cells and channels of |log correction|
};

// Levels the valid samples of `warped` (a buffer's, painted as `painted`) in place against
// the texels `kept` marks (CV_8U, the rectangle's size; 255: seen by the frame, keeping the
// stored sample; their samples still in warped->bgr). Nothing happens when `kept` is empty.
SeamLevelStats LevelSeams(const PaintedBuffer& painted, const cv::Mat& kept,
                          const SeamLevelOptions& options, WarpedBuffer* warped);

}  // namespace fresco
