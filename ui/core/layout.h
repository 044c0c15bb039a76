// Window layout maths for the app's panels, pure logic (no ImGui): where a window may be so
// that its title bar stays reachable.
#pragma once

namespace fresco {

struct LayoutRect {
  float x = 0, y = 0, w = 0, h = 0;
};

// The band windows live in: below the main menu bar, above the status bar.
struct LayoutBand {
  float display_w = 0, display_h = 0;
  float top_px = 0;     // the menu bar's height
  float bottom_px = 0;  // the status bar's height
};

// `window` moved (as little as possible) so that its title bar (`title_px` high) lies below
// the menu bar, above the status bar, and at least `grip_px` of it stays on screen sideways.
LayoutRect KeepTitleBarReachable(const LayoutRect& window, const LayoutBand& band, float title_px,
                                 float grip_px = 48);

}  // namespace fresco
