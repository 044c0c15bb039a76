// The app's scale on high-density screens: the monitor's content scale (GLFW's; 2 on a 4K
// screen set to 192 dpi) times the font scale the user steps to (StepFontScale). The default
// font is built at the next whole multiple of its 13 pixels at or above the scale, and shown
// at the scale (crisp at whole scales: 26 pixels at 2); the style's paddings, spacings and
// rounding are scaled with it.
#pragma once

namespace fresco {

inline constexpr float kMinUiScale = 0.5f, kMaxUiScale = 4.0f;

struct UiScale {
  float content = 1;  // the monitor's (GLFW's window content scale)
  float user = 1;     // the font scale (kFontScaleSteps), saved with the layout
  float Total() const;
};

// The font scales the user steps through (the status bar's A- and A+, Ctrl+- and Ctrl+=;
// Ctrl+0 goes back to 1): steps, not a slider, so the text growing under the cursor never
// carries a drag further than meant.
inline constexpr float kFontScaleSteps[] = {0.75f, 1.0f, 1.25f, 1.5f, 1.75f, 2.0f};

// The step after `current` towards larger (`direction` > 0) or smaller text, held at the
// ends; a scale between steps (an older layout file's) goes to the next step that way.
float StepFontScale(float current, int direction);

// The whole multiple of the default font's 13 pixels the atlas is built at for `total`.
int FontAtlasMultiple(float total);

// Rebuilds the current ImGui context's font atlas and style for `total` when `*applied` is
// another scale, and sets `*applied`; true when it did (the GL app uploads the font texture
// again). The style restarts from ImGui's dark style.
bool ApplyUiScale(float total, float* applied);

}  // namespace fresco
