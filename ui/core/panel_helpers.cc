#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <imgui_internal.h>

#include "pipeline/poses/colmap_log_progress.h"
#include "ui/core/job_estimate.h"
#include "ui/core/layout.h"
#include "ui/core/panel.h"

namespace fresco {

namespace {

// A panel's text wraps at its edge, but never narrower than kMinWrapEm font sizes: in a
// panel narrower than that, a caption runs out of sight (the title's tooltip and a wider
// tile show it) instead of standing one letter per line.
constexpr float kMinWrapEm = 8;

void PushPanelTextWrap() {
  const float min_px = kMinWrapEm * ImGui::GetFontSize();
  const float start = ImGui::GetCursorPosX();
  ImGui::PushTextWrapPos(ImGui::GetWindowContentRegionMax().x - start < min_px ? start + min_px
                                                                               : 0.0f);
}

}  // namespace

std::string FittedTitle(const Panel& panel, float width) {
  const auto fits = [width](const std::string& text) {
    return ImGui::CalcTextSize(text.c_str()).x <= width;
  };
  if (fits(panel.Title())) return panel.Title();
  std::string shown = panel.ShortTitle();
  if (fits(shown)) return shown;
  while (shown.size() > 1 && !fits(shown + "..")) shown.pop_back();
  return shown + "..";
}

bool BeginPanel(Panel& panel) {
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  if (panel.tiled) {
    ImGui::SetNextWindowPos(panel.tile_pos, ImGuiCond_Always);
    ImGui::SetNextWindowSize(panel.tile_size, ImGuiCond_Always);
    // The title bar holds the title between its paddings, beside the close button.
    const ImGuiStyle& style = ImGui::GetStyle();
    const float title_width = panel.tile_size.x - 2 * style.FramePadding.x - ImGui::GetFontSize() -
                              style.ItemInnerSpacing.x;
    const std::string name = FittedTitle(panel, title_width) + PanelWindowId(panel.Title());
    const bool visible =
        ImGui::Begin(name.c_str(), &panel.open,
                     ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize |
                         ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoSavedSettings);
    // Text wraps at the panel's edge instead of running out of a narrow tile (ImGui resets
    // the wrap position at every Begin, so nothing needs popping).
    PushPanelTextWrap();
    const float title_bottom = ImGui::GetWindowPos().y + ImGui::GetFrameHeight();
    const bool on_title = ImGui::IsWindowHovered() && ImGui::GetIO().MousePos.y < title_bottom;
    if (on_title && ImGui::IsMouseDoubleClicked(ImGuiMouseButton_Left))
      panel.maximise_requested = true;
    if (on_title && ImGui::IsMouseClicked(ImGuiMouseButton_Right)) panel.swap_menu_requested = true;
    if (on_title)  // the whole title where a narrow tile cuts it short
      ImGui::SetTooltip("%s (double-click: maximise / restore; right-click: swap places)",
                        panel.Title());
    return visible;
  }
  const float sx = display.x / 1600.0f, sy = display.y / 1000.0f;
  ImGui::SetNextWindowPos(ImVec2(panel.default_pos.x * sx, panel.default_pos.y * sy),
                          ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(panel.default_size.x * sx, panel.default_size.y * sy),
                           ImGuiCond_FirstUseEver);
  const bool visible =
      ImGui::Begin((panel.Title() + PanelWindowId(panel.Title())).c_str(), &panel.open);
  PushPanelTextWrap();
  // However it was dragged, the title bar stays below the menu bar and on screen.
  const ImVec2 pos = ImGui::GetWindowPos(), size = ImGui::GetWindowSize();
  const LayoutBand band{display.x, display.y, ImGui::GetFrameHeight(), StatusBarHeight()};
  const LayoutRect kept =
      KeepTitleBarReachable({pos.x, pos.y, size.x, size.y}, band, ImGui::GetFrameHeight());
  if (kept.x != pos.x || kept.y != pos.y) ImGui::SetWindowPos(ImVec2(kept.x, kept.y));
  return visible;
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

float ButtonWidth(const char* label) {
  return ImGui::CalcTextSize(label, nullptr, true).x + 2 * ImGui::GetStyle().FramePadding.x;
}

void FitNextItem(const char* following, float min_px) {
  float width = ImGui::GetContentRegionAvail().x;
  if (following) width -= ButtonWidth(following) + ImGui::GetStyle().ItemSpacing.x;
  ImGui::SetNextItemWidth(std::max(min_px, width));
}

std::string FitLabelledItem(const std::string& label) {
  if (ImGui::CalcItemWidth() >= kMinFieldEm * ImGui::GetFontSize()) return label;
  const size_t hidden = label.find("##");
  ImGui::TextUnformatted(label.substr(0, hidden).c_str());
  ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x);
  return hidden == std::string::npos ? "##" + label : label.substr(hidden);
}

void SameLineIfFits(float next_width) {
  const float x = ImGui::GetItemRectMax().x + ImGui::GetStyle().ItemSpacing.x;
  if (x + next_width <= ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x)
    ImGui::SameLine();
}

void SameLineInFieldColumn() {
  constexpr float kColumnPx = 80, kDefaultFontPx = 13;
  const ImGuiWindow* w = ImGui::GetCurrentWindow();
  // SameLine's offsets count from here (the window's left, or the table column's).
  const float origin = w->Pos.x - w->Scroll.x + w->DC.GroupOffset.x + w->DC.ColumnsOffset.x;
  const float past_label = ImGui::GetItemRectMax().x - origin + ImGui::GetStyle().ItemSpacing.x;
  ImGui::SameLine(std::max(kColumnPx / kDefaultFontPx * ImGui::GetFontSize(), past_label));
}

int ShownFrame(const RunnerSnapshot& snap) {
  return snap.seek_target >= 0 ? snap.seek_target : snap.frame;
}

std::string FrameLabel(const RunnerSnapshot& snap) {
  const std::string target = std::to_string(snap.seek_target);
  if (snap.seek_target >= 0 && snap.frame < 0 && snap.seek_state >= 0)
    return "seeking to frame " + target + ": from the state saved before frame " +
           std::to_string(snap.seek_state);
  if (snap.seek_target >= 0 && snap.frame < 0) return "seeking to frame " + target + ": reopening";
  if (snap.seek_target >= 0)
    return "seeking to frame " + target + ": at " + std::to_string(snap.frame);
  if (snap.frame < 0) return "no frame painted yet";
  return "frame " + std::to_string(snap.frame);
}

std::string StatusText(const RunnerSnapshot& snap) {
  if (snap.step_text.empty() || snap.status.rfind(snap.step_text, 0) != 0) return snap.status;
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - snap.step_started).count();
  if (snap.step_fraction < 0) return snap.step_text + ", " + DurationText(elapsed_s) + " elapsed";
  return snap.step_text + ", " + ElapsedAndRemainingText(elapsed_s, snap.step_fraction);
}

void ShowMetrics(const std::map<std::string, double>& metrics) {
  if (!ImGui::BeginTable("metrics", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV))
    return;
  ImGui::PushTextWrapPos(-1.0f);  // names do not break mid-word
  for (const auto& [name, value] : metrics) {
    ImGui::TableNextRow();
    ImGui::TableSetColumnIndex(0);
    ImGui::TextUnformatted(name.c_str());  // clipped by its column, whole in a tooltip
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", name.c_str());
    ImGui::TableSetColumnIndex(1);
    if (std::isnan(value))
      ImGui::TextDisabled("-");
    else if (value == std::floor(value) && std::abs(value) < 1e12)
      ImGui::Text("%.0f", value);
    else
      ImGui::Text("%.4g", value);
  }
  ImGui::PopTextWrapPos();
  ImGui::EndTable();
}

float ProgressBarWithText(float fraction, const std::string& text, float width) {
  const ImGuiStyle& style = ImGui::GetStyle();
  const float bar = width > 0 ? width : ImGui::GetContentRegionAvail().x + width;
  const bool fits = ImGui::CalcTextSize(text.c_str()).x + 2 * style.FramePadding.x <= bar;
  char percent[16];
  std::snprintf(percent, sizeof(percent), "%.0f %%", 100.0f * std::clamp(fraction, 0.0f, 1.0f));
  ImGui::ProgressBar(fraction, ImVec2(bar, 0), fits ? text.c_str() : percent);
  if (fits) return 0;
  ImGui::TextWrapped("%s", text.c_str());
  return ImGui::GetItemRectSize().y / ImGui::GetTextLineHeight();
}

void ColmapProgressBar(const PosesSnapshot& snap) {
  if (!snap.busy) return;
  const auto now = std::chrono::steady_clock::now();
  const double seconds =
      std::chrono::duration<double>(now - (snap.steps > 0 ? snap.step_started : snap.started))
          .count();
  if (snap.steps == 0) {
    ProgressBarWithText(0.0f, DurationText(seconds) + " elapsed");
    return;
  }
  // How far the step has got, from the progress lines COLMAP writes to its log.
  const ColmapStepProgress step =
      ReadColmapStepProgress(ReadFileTail(snap.step_log, 4096), snap.step_images);
  // Appended piece by piece (GCC 12 warns, wrongly, on "literal" + std::string here).
  std::string text = "step ";
  text.append(std::to_string(snap.step)).append("/").append(std::to_string(snap.steps));
  text.append(" ").append(snap.step_name);
  if (step.known)
    text.append(" ")
        .append(std::to_string(step.done))
        .append("/")
        .append(std::to_string(step.total))
        .append(" images");
  text.append(": ").append(ElapsedAndRemainingText(seconds, step.Fraction()));
  if (RemainingSeconds(seconds, step.Fraction()) >= kFinishingBelowSeconds) text += " in this step";
  const float fraction = (snap.step - 1 + static_cast<float>(step.Fraction())) / snap.steps;
  ProgressBarWithText(fraction, text);
}

}  // namespace fresco
