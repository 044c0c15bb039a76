// Stage panels, one per pipeline stage: the stage's metrics and debug images for the current
// frame (any stage that reports images gets its panel with one registration line), plus the
// input frame and the painted buffers.
#include <algorithm>
#include <cctype>

#include "ui/core/image_view.h"
#include "ui/core/natural_sort.h"
#include "ui/core/panel.h"
#include "ui/panels/panels.h"

namespace fresco {
namespace {

// The image a stage panel shows first: a warped frame, else a painted buffer, else the
// first name; among several, the largest (most pixels; ties: the first in natural order),
// not a sliver of a buffer that happens to have the highest number.
std::string DefaultImage(const std::map<std::string, cv::Mat>& images,
                         const std::vector<std::string>& names) {
  for (const char* prefix : {"warped", "painted"}) {
    std::string best;
    double best_area = -1;
    for (const std::string& n : names) {
      if (n.rfind(prefix, 0) != 0) continue;
      const double area = static_cast<double>(images.at(n).total());
      if (area > best_area) best = n, best_area = area;
    }
    if (!best.empty()) return best;
  }
  return names.front();
}

}  // namespace

std::string NoDebugImagesNote(const RunnerSnapshot& snap) {
  if (snap.playing || snap.seek_target >= 0) return "(debug images appear when paused or stepping)";
  if (!snap.report_has_images)
    return "(frame " + std::to_string(snap.report.frame) +
           " was painted while playing, without debug images: Step or Apply (F5) paints one "
           "with them)";
  return "(this stage drew no debug image for this frame)";
}

namespace {

class StagePanel : public Panel {
 public:
  StagePanel(std::string stage, std::string title)
      : stage_(std::move(stage)), title_(std::move(title)), short_title_(stage_) {
    short_title_[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(stage_[0])));
  }
  const char* Title() const override { return title_.c_str(); }
  const char* ShortTitle() const override { return short_title_.c_str(); }  // "Depth", ...

  void Draw(UiContext& ui) override {
    if (!BeginPanel(*this)) {
      ImGui::End();
      return;
    }
    const RunnerSnapshot& snap = *ui.snapshot;
    const StageReport* stage = nullptr;
    for (const StageReport& s : snap.report.stages)
      if (s.name == stage_) stage = &s;
    // An `auto` mode that decided off drops its stage: say why.
    const AutoDecision* decision = stage_ == "refine"       ? &snap.report.decisions.refine
                                   : stage_ == "background" ? &snap.report.decisions.background
                                                            : nullptr;
    if (!stage) {
      const bool decided_off = decision && decision->is_auto() && !snap.report.stages.empty();
      ImGui::TextDisabled("%s", !snap.report.skipped_reason.empty()
                                    ? snap.report.skipped_reason.c_str()
                                : snap.report.stages.empty() ? "no frame painted yet"
                                : decided_off ? "stage not running: mode auto decided off"
                                              : "stage not running (off in the pipeline settings)");
      if (decided_off) ImGui::TextWrapped("auto: %s", decision->Describe().c_str());
      ImGui::End();
      return;
    }
    ImGui::Text("frame %d: %.2f ms", snap.report.frame, stage->wall_ms);
    note_.clear();
    std::vector<std::string> names;
    for (const auto& [name, image] : stage->images) names.push_back(name);
    SortNaturally(&names);
    if (!names.empty()) {
      if (std::find(names.begin(), names.end(), selected_) == names.end())
        selected_ = DefaultImage(stage->images, names);
      FitNextItem("image");
      ImGui::SetNextItemWidth(std::min(200.0f, ImGui::CalcItemWidth()));
      const bool open_combo = ImGui::BeginCombo("image", selected_.c_str());
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", selected_.c_str());
      if (open_combo) {
        for (const std::string& n : names)
          if (ImGui::Selectable(n.c_str(), n == selected_)) selected_ = n;
        ImGui::EndCombo();
      }
      ColourScale scale;
      const bool false_colour = FalseColourScaleOf(stage_, selected_, &scale);
      view_.Draw(ui, stage_ + "/" + selected_, stage->images.at(selected_), snap.version,
                 false_colour ? &scale : nullptr);
    } else {
      note_ = NoDebugImagesNote(snap);
      ImGui::TextDisabled("%s", note_.c_str());
    }
    std::vector<std::string> note_keys;  // buffer2 before buffer19
    for (const auto& [key, text] : stage->notes) note_keys.push_back(key);
    SortNaturally(&note_keys);
    for (const std::string& key : note_keys)
      ImGui::TextWrapped("%s: %s", key.c_str(), stage->notes.at(key).c_str());
    ShowMetrics(stage->metrics);
    ImGui::End();
  }

  std::map<std::string, std::string> Report() const override {
    std::map<std::string, std::string> report{{"image", selected_}, {"note", note_}};
    view_.ReportInto(&report);
    return report;
  }

 private:
  std::string stage_, title_, short_title_, selected_;
  std::string note_;  // why no debug image is shown ("" when one is)
  ImageView view_;
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
    const int streams = static_cast<int>(snap.stream_frames.size());
    if (streams > 1) {  // several cameras: the latest frame painted, or one stream's latest
      ImGui::RadioButton("latest", &shown_, -1);
      for (int i = 0; i < streams; ++i) {
        ImGui::SameLine();
        ImGui::RadioButton(("stream " + std::to_string(i)).c_str(), &shown_, i);
      }
      shown_ = std::clamp(shown_, -1, streams - 1);
    } else {
      shown_ = -1;
    }
    ImGui::Text("%s %s%s", FrameLabel(snap).c_str(), snap.frame_name.c_str(),
                snap.has_pose ? "" : " (no pose)");
    const bool latest = shown_ < 0 || shown_ == snap.stream;
    if (latest) {
      view_.Draw(ui, "input", snap.frame_bgr, snap.version);
    } else if (snap.stream_frames[shown_].empty()) {
      ImGui::TextDisabled("stream %d: no frame of it shown yet", shown_);
    } else {
      ImGui::TextDisabled("stream %d: its latest frame shown", shown_);
      view_.Draw(ui, "input", snap.stream_frames[shown_], snap.version);
    }
    ImGui::End();
  }
  std::map<std::string, std::string> Report() const override {
    std::map<std::string, std::string> report;
    view_.ReportInto(&report);
    report["stream"] = shown_ < 0 ? "latest" : std::to_string(shown_);
    return report;
  }

 private:
  ImageView view_;
  int shown_ = -1;  // the stream whose latest frame is shown; -1: the latest of any stream
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
    if (snap.geometry_version != shown_geometry_ && snap.geometry) {
      // A new session: start on its largest buffer (most texels).
      const auto& texels = snap.geometry->buffer_texels;
      buffer_ =
          texels.empty()
              ? 0
              : static_cast<int>(std::max_element(texels.begin(), texels.end()) - texels.begin());
      shown_geometry_ = snap.geometry_version;
    }
    buffer_ = std::clamp(buffer_, 0, n - 1);
    ImGui::SetNextItemWidth(120);
    ImGui::SliderInt("buffer", &buffer_, 0, n - 1);
    caption_lines_ = 0;
    if (snap.geometry && buffer_ < static_cast<int>(snap.geometry->groups.size())) {
      // Beside the slider where it fits, else below it (not wrapped a few letters a line).
      const std::string caption = std::to_string(snap.geometry->groups[buffer_].triangles.size()) +
                                  " triangles, " +
                                  std::to_string(snap.geometry->buffer_texels[buffer_]) + " texels";
      SameLineIfFits(ImGui::CalcTextSize(caption.c_str()).x);
      ImGui::TextUnformatted(caption.c_str());
      caption_lines_ = ImGui::GetItemRectSize().y / ImGui::GetTextLineHeight();
    }
    view_.Draw(ui, "painted/" + std::to_string(buffer_), (*snap.painted)[buffer_],
               snap.painted_version);
    ImGui::End();
  }
  std::map<std::string, std::string> Report() const override {
    std::map<std::string, std::string> report{{"buffer", std::to_string(buffer_)},
                                              {"caption lines", std::to_string(caption_lines_)}};
    view_.ReportInto(&report);
    return report;
  }

 private:
  int buffer_ = 0;
  float caption_lines_ = 0;  // the buffer's caption, in lines of text
  uint64_t shown_geometry_ = 0;
  ImageView view_;
};

}  // namespace

std::unique_ptr<Panel> MakeStagePanel(const std::string& stage, const std::string& title) {
  return std::make_unique<StagePanel>(stage, title);
}
std::unique_ptr<Panel> MakeInputFramePanel() { return std::make_unique<InputFramePanel>(); }
std::unique_ptr<Panel> MakePaintedBuffersPanel() { return std::make_unique<PaintedBuffersPanel>(); }

}  // namespace fresco
