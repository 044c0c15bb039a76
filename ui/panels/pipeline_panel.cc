// Pipeline: play, pause, step, seek, restart; live sources' state and the Record toggle
// (live_status_section.h); and every pipeline setting of the project file, one widget each
// made from its declaration (setting_widgets.h), edited in the project (undoable) and
// applied by restarting the worker.
#include <algorithm>
#include <chrono>
#include <cstdio>

#include "ui/core/job_estimate.h"
#include "ui/core/panel.h"
#include "ui/panels/live_status_section.h"
#include "ui/panels/panels.h"
#include "ui/panels/setting_widgets.h"

namespace fresco {
namespace {

class PipelinePanel : public Panel {
 public:
  PipelinePanel() = default;
  PipelinePanel(const PipelinePanel&) = delete;  // settings_ points into edit_
  PipelinePanel& operator=(const PipelinePanel&) = delete;

  const char* Title() const override { return "Pipeline"; }

  void Draw(UiContext& ui) override {
    if (!BeginPanel(*this)) {
      ImGui::End();
      return;
    }
    const RunnerSnapshot& snap = *ui.snapshot;
    AppState& state = *ui.state;
    ImGui::BeginDisabled(!state.has_project);
    if (snap.playing) {
      if (ImGui::Button("Pause")) ui.runner->Pause();
    } else if (ImGui::Button("Play")) {
      ui.runner->Play();
    }
    ImGui::SameLine();
    // A file source can go back (painting on from the nearest state saved on the way).
    ImGui::BeginDisabled(snap.live.active || snap.frame < 1);
    if (ImGui::Button("<")) PostSeek(ui, snap, std::max(0, ShownFrame(snap) - 1));
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
      ImGui::SetTooltip(
          "step back one frame (paints on from the nearest of the states saved "
          "every few frames)");
    ImGui::EndDisabled();
    ImGui::SameLine();
    if (ImGui::Button("Step")) ui.runner->Step();
    ImGui::SameLine();
    if (ImGui::Button("Restart")) ui.runner->Restart(state.project);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("start again from the first frame");
    if (snap.live.active) {  // a live source has no end to seek to
      SameLineIfFits(ImGui::CalcTextSize("live frame 000000").x);
      ImGui::Text("live frame %d", snap.frame);
    } else {
      const int last = snap.geometry ? std::max(0, snap.geometry->num_frames - 1) : 0;
      // The slider shows the frame asked for until the worker has taken the seek up.
      if (snap.version > posted_version_) posted_seek_ = -1;
      // The slider on a line of its own, as wide as the panel allows.
      char of_last[32];
      std::snprintf(of_last, sizeof(of_last), "/ %d", last);
      ImGui::SetNextItemWidth(std::max(60.0f, ImGui::GetContentRegionAvail().x -
                                                  ImGui::CalcTextSize(of_last).x -
                                                  ImGui::GetStyle().ItemSpacing.x));
      const float x = ImGui::GetCursorScreenPos().x, y = ImGui::GetCursorScreenPos().y;
      if (!slider_active_) seek_ = posted_seek_ >= 0 ? posted_seek_ : std::max(0, ShownFrame(snap));
      ImGui::SliderInt("##seek", &seek_, 0, last, "frame %d");
      slider_active_ = ImGui::IsItemActive();
      slider_rect_[0] = x, slider_rect_[1] = y;
      slider_rect_[2] = ImGui::GetItemRectSize().x, slider_rect_[3] = ImGui::GetItemRectSize().y;
      if (ImGui::IsItemDeactivatedAfterEdit()) PostSeek(ui, snap, seek_);
      ImGui::SameLine();
      ImGui::TextUnformatted(of_last);
    }
    ImGui::EndDisabled();
    if (snap.seek_target >= 0) {  // a seek (back: from the nearest saved state) under way
      const int from = std::max(0, snap.seek_from);  // painted on from there
      const float done = snap.frame < from ? 0.0f
                                           : static_cast<float>(snap.frame + 1 - from) /
                                                 static_cast<float>(snap.seek_target + 1 - from);
      // Elapsed and remaining time, from when this panel first saw the seek.
      if (seek_seen_ != snap.seek_target) {
        seek_seen_ = snap.seek_target;
        seek_started_ = std::chrono::steady_clock::now();
      }
      const double elapsed_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - seek_started_).count();
      // The bar leaves room for Stop at any font scale; its text goes on a line of its own
      // below (wrapped at spaces) where the bar is narrower than it, instead of being cut.
      const ImGuiStyle& style = ImGui::GetStyle();
      const float stop = ImGui::CalcTextSize("Stop").x + 2 * style.FramePadding.x;
      const float bar = ImGui::GetContentRegionAvail().x - stop - style.ItemSpacing.x;
      seek_text_ = FrameLabel(snap) + ", " + ElapsedAndRemainingText(elapsed_s, done);
      const bool fits = ImGui::CalcTextSize(seek_text_.c_str()).x + 2 * style.FramePadding.x <= bar;
      char percent[16];
      std::snprintf(percent, sizeof(percent), "%.0f %%", 100.0f * done);
      ImGui::ProgressBar(done, ImVec2(bar, 0), fits ? seek_text_.c_str() : percent);
      seek_bar_width_ = bar;
      ImGui::SameLine();
      if (ImGui::Button("Stop")) ui.runner->Pause();  // keeps the frames painted so far
      stop_right_ = ImGui::GetItemRectMax().x;
      window_right_ = ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x;
      seek_text_lines_ = 0;
      if (!fits) {
        ImGui::TextWrapped("%s", seek_text_.c_str());
        seek_text_lines_ = ImGui::GetItemRectSize().y / ImGui::GetTextLineHeight();
      }
    } else {
      seek_seen_ = -1;
    }
    status_ = StatusText(snap);
    ImGui::TextWrapped("%s", status_.c_str());
    if (snap.geometry)
      ImGui::Text("%zu base buffers, texel %.4f m, coverage %.1f %%", snap.geometry->groups.size(),
                  snap.geometry->texel_size_m, 100.0 * snap.coverage);
    live_.Draw(ui, snap.live);

    ImGui::Separator();
    ImGui::TextDisabled("Settings (Apply restarts painting)");
    if (!ImGui::IsAnyItemActive()) edit_.pipeline = state.project.pipeline;
    // Widgets take what the longest label leaves, so no label runs out of a narrow panel.
    ImGui::PushItemWidth(-ImGui::CalcTextSize("anchor window frames").x -
                         ImGui::GetStyle().ItemInnerSpacing.x);
    // Every pipeline setting the project file has, by section, each with the range the file
    // accepts and its help as the tooltip (pipeline/core/settings.h).
    bool commit = false;
    std::string section;
    bool open = true;
    // Bound to edit_'s fields once (the panel and edit_ stay put), not rebuilt every frame.
    if (settings_.empty()) settings_ = DescribeSettings(&edit_);
    for (const Setting& setting : settings_) {
      if (setting.key.compare(0, 9, "pipeline.") != 0) continue;
      if (setting.Section() != section) {
        if (!section.empty() && open && section != "pipeline") ImGui::TreePop();
        section = setting.Section();
        open = section == "pipeline" ||
               ImGui::TreeNodeEx(section.c_str() + 9, ImGuiTreeNodeFlags_DefaultOpen);
      }
      if (!open) continue;
      ImGui::PushID(setting.key.c_str());
      commit |= DrawSettingWidget(setting);
      ImGui::PopID();
    }
    if (!section.empty() && open && section != "pipeline") ImGui::TreePop();
    if (commit && !(edit_.pipeline == state.project.pipeline)) {
      state.BeginEdit();
      state.project.pipeline = edit_.pipeline;
    }
    ImGui::PopItemWidth();
    ImGui::BeginDisabled(!state.has_project);
    if (ImGui::Button("Apply")) ApplyProject(ui);
    ImGui::EndDisabled();
    ImGui::End();
  }

  std::map<std::string, std::string> Report() const override {
    auto report = live_.report();
    report["seek"] = std::to_string(seek_);
    char rect[64];
    std::snprintf(rect, sizeof(rect), "%.0f %.0f %.0f %.0f", slider_rect_[0], slider_rect_[1],
                  slider_rect_[2], slider_rect_[3]);
    report["seek slider"] = rect;
    // The seek's progress: its text, the bar's width, the lines the text takes below it (0:
    // in the bar), and the right edges of Stop and of the panel's content.
    report["seek text"] = seek_text_;
    report["seek bar width"] = std::to_string(seek_bar_width_);
    report["seek text lines"] = std::to_string(seek_text_lines_);
    report["seek stop right"] = std::to_string(stop_right_);
    report["panel right"] = std::to_string(window_right_);
    report["status"] = status_;  // the worker's status as shown
    return report;
  }

 private:
  void PostSeek(UiContext& ui, const RunnerSnapshot& snap, int frame) {
    ui.runner->Seek(frame);
    posted_seek_ = frame;
    posted_version_ = snap.version;
  }

  std::string status_;
  int seek_ = 0;
  std::string seek_text_;
  float seek_bar_width_ = 0, seek_text_lines_ = 0, stop_right_ = 0, window_right_ = 0;
  int seek_seen_ = -1;  // the seek target whose progress is shown, and when it was first seen
  std::chrono::steady_clock::time_point seek_started_;
  int posted_seek_ = -1;         // a seek posted, not yet in a snapshot
  uint64_t posted_version_ = 0;  // the snapshot version when it was posted
  bool slider_active_ = false;
  float slider_rect_[4] = {0, 0, 0, 0};
  Project edit_;                   // its pipeline: the settings being edited
  std::vector<Setting> settings_;  // edit_'s settings, bound to its fields
  LiveStatusSection live_;
};

}  // namespace

std::unique_ptr<Panel> MakePipelinePanel() { return std::make_unique<PipelinePanel>(); }

}  // namespace fresco
