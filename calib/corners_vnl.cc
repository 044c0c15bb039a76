#include "calib/corners_vnl.h"

#include <cstdio>

#include "pipeline/core/atomic_file.h"

namespace fresco::calib {

std::string CornersVnlText(const std::vector<BoardView>& views, const BoardSpec& spec) {
  const BoardGrid grid = MakeBoardGrid(spec);
  const int points = grid.width_n * grid.height_n;
  std::string text = "# filename x y level\n";
  for (const BoardView& view : views) {
    std::vector<const CornerObservation*> at(points, nullptr);
    for (const CornerObservation& c : view.corners) at[grid.grid_index_of_corner[c.id]] = &c;
    for (int g = 0; g < points; ++g) {
      char row[128];
      if (at[g])
        std::snprintf(row, sizeof(row), " %.6f %.6f 0\n", at[g]->pixel.x(), at[g]->pixel.y());
      else
        std::snprintf(row, sizeof(row), " - - -\n");
      text += view.name + row;
    }
  }
  return text;
}

Status WriteCornersVnl(const std::string& path, const std::vector<BoardView>& views,
                       const BoardSpec& spec) {
  return WriteFileAtomic(path, CornersVnlText(views, spec));
}

}  // namespace fresco::calib
