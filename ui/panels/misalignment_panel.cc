// Misalignment review: the painted model (as it was before the current frame) rendered into
// the frame's view, shown against the frame as a blink, an overlay or a heat map of their
// difference; the per-frame difference along the sequence; the worst frames, one click away.
#include <algorithm>
#include <cmath>
#include <numeric>

#include <imgui.h>
#include <opencv2/imgproc.hpp>

#include "ui/core/image_view.h"
#include "ui/core/panel.h"
#include "ui/panels/panels.h"

namespace fresco {
namespace {

class MisalignmentPanel : public Panel {
 public:
  const char* Title() const override { return "Misalignment"; }

  void Draw(UiContext& ui) override {
    if (!BeginPanel(*this)) {
      ImGui::End();
      return;
    }
    const RunnerSnapshot& snap = *ui.snapshot;
    const float radio = ImGui::GetFrameHeight() + ImGui::GetStyle().ItemInnerSpacing.x;
    ImGui::RadioButton("heat map", &mode_, 0);
    SameLineIfFits(radio + ImGui::CalcTextSize("overlay").x);
    ImGui::RadioButton("overlay", &mode_, 1);
    SameLineIfFits(radio + ImGui::CalcTextSize("blink").x);
    ImGui::RadioButton("blink", &mode_, 2);
    if (snap.rephoto_bgr.empty() || snap.frame_bgr.empty()) {
      ImGui::TextDisabled("(shown for paused or stepped frames once something is painted)");
    } else if (mode_ == 0) {
      const ColourScale scale = DifferenceHeatScale();
      view_.Draw(ui, "misalignment/heat", snap.difference_heat, snap.version, &scale);
    } else {
      cv::Mat frame;
      cv::resize(snap.frame_bgr, frame, snap.rephoto_bgr.size(), 0, 0, cv::INTER_AREA);
      if (mode_ == 1) {
        cv::Mat overlay;
        cv::addWeighted(frame, 0.5, snap.rephoto_bgr, 0.5, 0.0, overlay);
        view_.Draw(ui, "misalignment/overlay", overlay, snap.version);
      } else {
        const bool show_frame = static_cast<int>(ImGui::GetTime() * 2.0) % 2 == 0;
        view_.Draw(ui, show_frame ? "misalignment/frame" : "misalignment/rephoto",
                   show_frame ? frame : snap.rephoto_bgr, snap.version);
        ImGui::TextDisabled(show_frame ? "frame" : "painted model");
      }
    }
    // The difference along the sequence (grey levels, 0..255), and the worst frames.
    const std::vector<float>& d = snap.misalignment;
    std::vector<float> plot(d.size());
    for (size_t i = 0; i < d.size(); ++i) plot[i] = std::isnan(d[i]) ? 0.0f : d[i];
    ImGui::PlotLines("##difference", plot.data(), static_cast<int>(plot.size()), 0,
                     "mean |grey difference| to the buffers, per frame", 0.0f, FLT_MAX,
                     ImVec2(ImGui::GetContentRegionAvail().x, 80));
    if (!snap.refine_before_px.empty()) {
      // The refine stage's residuals along the sequence (0 where nothing was matched).
      std::vector<float> before(snap.refine_before_px.size()), after(snap.refine_after_px.size());
      for (size_t i = 0; i < before.size(); ++i)
        before[i] = std::isnan(snap.refine_before_px[i]) ? 0.0f : snap.refine_before_px[i];
      for (size_t i = 0; i < after.size(); ++i)
        after[i] = std::isnan(snap.refine_after_px[i]) ? 0.0f : snap.refine_after_px[i];
      const float top = before.empty() ? 1.0f : *std::max_element(before.begin(), before.end());
      ImGui::PlotLines("##refine_before", before.data(), static_cast<int>(before.size()), 0,
                       "refinement residual before, texels", 0.0f, top,
                       ImVec2(ImGui::GetContentRegionAvail().x, 50));
      ImGui::PlotLines("##refine_after", after.data(), static_cast<int>(after.size()), 0, "after",
                       0.0f, top, ImVec2(ImGui::GetContentRegionAvail().x, 50));
    }
    std::vector<size_t> order(d.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return plot[a] > plot[b]; });
    ImGui::Text("worst frames:");
    for (size_t k = 0; k < std::min<size_t>(5, order.size()); ++k) {
      const size_t i = order[k];
      if (plot[i] <= 0) break;
      const int frame = snap.frames_painted[i];
      ImGui::PushID(static_cast<int>(k));
      if (ImGui::SmallButton("go")) ui.runner->Seek(frame);
      ImGui::PopID();
      ImGui::SameLine();
      ImGui::Text("frame %d: %.2f", frame, plot[i]);
    }
    ImGui::End();
  }

  std::map<std::string, std::string> Report() const override {
    std::map<std::string, std::string> report;
    view_.ReportInto(&report);
    return report;
  }

 private:
  int mode_ = 0;
  ImageView view_;  // one zoom for the three modes: the same pixels compared
};

}  // namespace

std::unique_ptr<Panel> MakeMisalignmentPanel() { return std::make_unique<MisalignmentPanel>(); }

}  // namespace fresco
