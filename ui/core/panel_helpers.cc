#include <cmath>

#include "ui/core/panel.h"

namespace fresco {

bool BeginPanel(Panel& panel) {
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  const float sx = display.x / 1600.0f, sy = display.y / 1000.0f;
  ImGui::SetNextWindowPos(ImVec2(panel.default_pos.x * sx, panel.default_pos.y * sy),
                          ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(panel.default_size.x * sx, panel.default_size.y * sy),
                           ImGuiCond_FirstUseEver);
  return ImGui::Begin(panel.Title(), &panel.open);
}

bool BeginOverlayPanel(Panel& panel, bool has_worker, const char* worker) {
  ImGui::SetNextWindowBgAlpha(1.0f);
  if (!BeginPanel(panel)) {
    ImGui::End();
    return false;
  }
  if (!has_worker) {
    ImGui::TextDisabled("(no %s)", worker);
    ImGui::End();
    return false;
  }
  return true;
}

void ShowImage(UiContext& ui, const std::string& key, const cv::Mat& image, uint64_t version,
               float max_width) {
  if (image.empty()) {
    ImGui::TextDisabled("(no image)");
    return;
  }
  const float avail = ImGui::GetContentRegionAvail().x;
  const float width = std::max(16.0f, max_width > 0 ? std::min(max_width, avail) : avail);
  const float height = width * image.rows / std::max(1, image.cols);
  ImGui::Image(ui.textures->Get(key, image, version), ImVec2(width, height));
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s: %d x %d", key.c_str(), image.cols, image.rows);
}

void ShowMetrics(const std::map<std::string, double>& metrics) {
  if (!ImGui::BeginTable("metrics", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV))
    return;
  for (const auto& [name, value] : metrics) {
    ImGui::TableNextRow();
    ImGui::TableSetColumnIndex(0);
    ImGui::TextUnformatted(name.c_str());
    ImGui::TableSetColumnIndex(1);
    if (std::isnan(value))
      ImGui::TextDisabled("-");
    else if (value == std::floor(value) && std::abs(value) < 1e12)
      ImGui::Text("%.0f", value);
    else
      ImGui::Text("%.4g", value);
  }
  ImGui::EndTable();
}

}  // namespace fresco
