#include "ui/core/layout.h"

#include <algorithm>

namespace fresco {

LayoutRect KeepTitleBarReachable(const LayoutRect& window, const LayoutBand& band, float title_px,
                                 float grip_px) {
  LayoutRect r = window;
  const float max_y = std::max(band.top_px, band.display_h - band.bottom_px - title_px);
  r.y = std::clamp(r.y, band.top_px, max_y);
  const float grip = std::min(grip_px, r.w);
  const float min_x = grip - r.w, max_x = std::max(min_x, band.display_w - grip);
  r.x = std::clamp(r.x, min_x, max_x);
  return r;
}

}  // namespace fresco
