// A picture of all painted base buffers at once (a contact sheet): each buffer scaled to a
// common cell height, side by side in rows, never-painted texels shown as a grey
// checkerboard, each cell labelled with its buffer number. `fresco run` writes it as
// DIR/buffers.png; the app can show the same image.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/paint/paint_update.h"

namespace fresco {

// CV_8UC3 (BGR), at most `max_width` pixels wide; cells `cell_height` pixels high.
cv::Mat BufferContactSheet(const std::vector<PaintedBuffer>& buffers, int max_width = 1600,
                           int cell_height = 240);

}  // namespace fresco
