#include "ui/panels/setting_widgets.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>

#include <imgui.h>

#include "ui/core/panel.h"

namespace fresco {
namespace {

void Tooltip(const Setting& s) {
  if (!ImGui::IsItemHovered()) return;
  ImGui::BeginTooltip();
  ImGui::PushTextWrapPos(ImGui::GetFontSize() * 32.0f);
  ImGui::TextUnformatted(s.help.c_str());
  ImGui::TextDisabled("%s  (%s)", s.key.c_str(), s.RangeText().c_str());
  ImGui::PopTextWrapPos();
  ImGui::EndTooltip();
}

// A finite bound for the drag widgets (ImGui needs one); values stay checked by the rule.
double Lowest(const Setting& s) {
  if (!std::isfinite(s.min)) return -1e9;
  return s.min_exclusive ? std::nextafter(s.min, std::numeric_limits<double>::infinity()) : s.min;
}

}  // namespace

std::string SettingLabel(const Setting& setting) {
  std::string label = setting.Name();
  std::replace(label.begin(), label.end(), '_', ' ');
  return label;
}

bool DrawSettingWidget(const Setting& s) {
  const bool fits_beside = s.kind == Setting::Kind::kBool || s.kind == Setting::Kind::kText;
  const std::string label = fits_beside ? SettingLabel(s) : FitLabelledItem(SettingLabel(s));
  bool done = false;
  switch (s.kind) {
    case Setting::Kind::kBool:
      done = ImGui::Checkbox(label.c_str(), s.flag);
      break;
    case Setting::Kind::kChoice: {
      int index = s.get_choice();
      if (ImGui::BeginCombo(label.c_str(), s.choices[index].c_str())) {
        for (int i = 0; i < static_cast<int>(s.choices.size()); ++i) {
          if (ImGui::Selectable(s.choices[i].c_str(), i == index) && i != index) {
            s.set_choice(i);
            done = true;
          }
        }
        ImGui::EndCombo();
      }
      break;
    }
    case Setting::Kind::kInt: {
      const int lo = static_cast<int>(std::max<double>(INT_MIN, std::ceil(Lowest(s))));
      const int hi = static_cast<int>(std::min<double>(INT_MAX, s.max));
      const float speed = std::max(1.0f, std::abs(static_cast<float>(*s.integer)) / 100.0f);
      ImGui::DragInt(label.c_str(), s.integer, speed, lo, hi, "%d", ImGuiSliderFlags_AlwaysClamp);
      done = ImGui::IsItemDeactivatedAfterEdit();
      break;
    }
    case Setting::Kind::kNumber: {
      const double lo = Lowest(s), hi = std::isfinite(s.max) ? s.max : 1e9;
      const float speed = static_cast<float>(std::max(1e-4, std::abs(*s.number) / 100.0));
      ImGui::DragScalar(label.c_str(), ImGuiDataType_Double, s.number, speed, &lo, &hi, "%.4g",
                        ImGuiSliderFlags_AlwaysClamp);
      done = ImGui::IsItemDeactivatedAfterEdit();
      break;
    }
    case Setting::Kind::kText:
      ImGui::TextDisabled("%s: %s", label.c_str(), s.ValueText().c_str());
      break;
  }
  Tooltip(s);
  return done;
}

}  // namespace fresco
