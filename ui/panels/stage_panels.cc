// Stage panels, one per pipeline stage: the stage's metrics and debug images for the current
// frame (any stage that reports images gets its panel with one registration line), plus the
// input frame and the painted buffers.
#include <algorithm>

#include "ui/core/panel.h"
#include "ui/panels/panels.h"

namespace fresco {
namespace {

class StagePanel : public Panel {
 public:
  StagePanel(std::string stage, std::string title)
      : stage_(std::move(stage)), title_(std::move(title)) {}
  const char* Title() const override { return title_.c_str(); }

  void Draw(UiContext& ui) override {
    if (!BeginPanel(*this)) {
      ImGui::End();
      return;
    }
    const RunnerSnapshot& snap = *ui.snapshot;
    const StageReport* stage = nullptr;
    for (const StageReport& s : snap.report.stages)
      if (s.name == stage_) stage = &s;
    if (!stage) {
      ImGui::TextDisabled(
          "%s", !snap.report.skipped_reason.empty() ? snap.report.skipped_reason.c_str()
                : snap.report.stages.empty()        ? "no frame painted yet"
                                             : "stage not running (off in the pipeline settings)");
      ImGui::End();
      return;
    }
    ImGui::Text("frame %d: %.2f ms", snap.report.frame, stage->wall_ms);
    std::vector<std::string> names;
    for (const auto& [name, image] : stage->images) names.push_back(name);
    if (!names.empty()) {
      if (std::find(names.begin(), names.end(), selected_) == names.end()) {
        // Prefer the warped frame, then the painted buffer, over masks.
        selected_ = names.front();
        for (const char* prefix : {"painted", "warped"})
          for (const std::string& n : names)
            if (n.rfind(prefix, 0) == 0) selected_ = n;
      }
      ImGui::SetNextItemWidth(200);
      if (ImGui::BeginCombo("image", selected_.c_str())) {
        for (const std::string& n : names)
          if (ImGui::Selectable(n.c_str(), n == selected_)) selected_ = n;
        ImGui::EndCombo();
      }
      ShowImage(ui, stage_ + "/" + selected_, stage->images.at(selected_), snap.version);
    } else {
      ImGui::TextDisabled("(debug images appear when paused or stepping)");
    }
    for (const auto& [key, text] : stage->notes)
      ImGui::TextWrapped("%s: %s", key.c_str(), text.c_str());
    ShowMetrics(stage->metrics);
    ImGui::End();
  }

 private:
  std::string stage_, title_, selected_;
};

class InputFramePanel : public Panel {
 public:
  const char* Title() const override { return "Input frame"; }
  void Draw(UiContext& ui) override {
    if (!BeginPanel(*this)) {
      ImGui::End();
      return;
    }
    const RunnerSnapshot& snap = *ui.snapshot;
    ImGui::Text("frame %d %s%s", snap.frame, snap.frame_name.c_str(),
                snap.has_pose ? "" : " (no pose)");
    ShowImage(ui, "input", snap.frame_bgr, snap.version);
    ImGui::End();
  }
};

class PaintedBuffersPanel : public Panel {
 public:
  const char* Title() const override { return "Painted buffers"; }
  void Draw(UiContext& ui) override {
    if (!BeginPanel(*this)) {
      ImGui::End();
      return;
    }
    const RunnerSnapshot& snap = *ui.snapshot;
    if (!snap.painted || snap.painted->empty()) {
      ImGui::TextDisabled("nothing painted yet");
      ImGui::End();
      return;
    }
    const int n = static_cast<int>(snap.painted->size());
    buffer_ = std::clamp(buffer_, 0, n - 1);
    ImGui::SetNextItemWidth(120);
    ImGui::SliderInt("buffer", &buffer_, 0, n - 1);
    if (snap.geometry && buffer_ < static_cast<int>(snap.geometry->groups.size())) {
      ImGui::SameLine();
      ImGui::Text("%zu triangles, %d texels", snap.geometry->groups[buffer_].triangles.size(),
                  snap.geometry->buffer_texels[buffer_]);
    }
    ShowImage(ui, "painted/" + std::to_string(buffer_), (*snap.painted)[buffer_],
              snap.painted_version);
    ImGui::End();
  }

 private:
  int buffer_ = 0;
};

}  // namespace

std::unique_ptr<Panel> MakeStagePanel(const std::string& stage, const std::string& title) {
  return std::make_unique<StagePanel>(stage, title);
}
std::unique_ptr<Panel> MakeInputFramePanel() { return std::make_unique<InputFramePanel>(); }
std::unique_ptr<Panel> MakePaintedBuffersPanel() { return std::make_unique<PaintedBuffersPanel>(); }

}  // namespace fresco
