// The app's layout between sessions: the splitters' places, the panels' places (after swaps)
// and the font scale, kept in
// CONFIG/fresco/layout.json (next to the recent projects). A file from a different panel
// arrangement (another number of splitters) is ignored, not an error.
#pragma once

#include <string>

#include "pipeline/core/status.h"
#include "ui/core/tile_layout.h"

namespace fresco {

struct SavedLayout {
  TileLayout layout = DefaultTileLayout();
  float font_scale = 1;  // View > font scale (UiScale::user)
};

// Writes {"fractions": [...], "panels": [...], "font_scale": s} atomically.
Status SaveLayoutFile(const std::string& path, const SavedLayout& saved);
// Reads what SaveLayoutFile wrote into `saved` (whose layout gives the expected splitters).
// A missing file leaves `saved` as it is (ok); a damaged one is an error naming the file
// and leaves it as it is too; fractions or panels for another arrangement are ignored (ok),
// and a file without "panels" (an older one) keeps the default places.
Status LoadLayoutFile(const std::string& path, SavedLayout* saved);

}  // namespace fresco
