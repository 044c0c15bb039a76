// mrcal's corners file (corners.vnl: "# filename x y level", one row per point of the board
// grid, W x H rows per image in mrcal's order, '-' for a point not observed), so that
// mrcal-calibrate-cameras can solve from exactly the corners Fresco detected.
#pragma once

#include <string>
#include <vector>

#include "calib/board.h"
#include "calib/observations.h"
#include "pipeline/core/status.h"

namespace fresco::calib {

std::string CornersVnlText(const std::vector<BoardView>& views, const BoardSpec& spec);
Status WriteCornersVnl(const std::string& path, const std::vector<BoardView>& views,
                       const BoardSpec& spec);

}  // namespace fresco::calib
