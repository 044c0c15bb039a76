#include "ui/core/ui_scale.h"

#include <iterator>

#include <algorithm>
#include <cmath>

#include <imgui.h>

namespace fresco {

float StepFontScale(float current, int direction) {
  if (direction > 0) {
    for (float step : kFontScaleSteps)
      if (step > current + 1e-3f) return step;
    return kFontScaleSteps[std::size(kFontScaleSteps) - 1];
  }
  for (size_t i = std::size(kFontScaleSteps); i-- > 0;)
    if (kFontScaleSteps[i] < current - 1e-3f) return kFontScaleSteps[i];
  return kFontScaleSteps[0];
}

float UiScale::Total() const { return std::clamp(content * user, kMinUiScale, kMaxUiScale); }

int FontAtlasMultiple(float total) {
  return std::max(1, static_cast<int>(std::ceil(total - 0.01f)));
}

bool ApplyUiScale(float total, float* applied) {
  if (total == *applied) return false;
  ImGuiIO& io = ImGui::GetIO();
  const int multiple = FontAtlasMultiple(total);
  io.Fonts->Clear();
  ImFontConfig config;
  config.SizePixels = 13.0f * static_cast<float>(multiple);
  io.Fonts->AddFontDefault(&config);
  unsigned char* pixels = nullptr;
  int width = 0, height = 0;
  io.Fonts->GetTexDataAsRGBA32(&pixels, &width, &height);  // built now, uploaded by the GL app
  io.FontGlobalScale = total / static_cast<float>(multiple);
  ImGuiStyle style;
  ImGui::StyleColorsDark(&style);
  style.ScaleAllSizes(total);
  ImGui::GetStyle() = style;
  *applied = total;
  return true;
}

}  // namespace fresco
