// Timing: milliseconds per stage for every painted frame, as curves, with the mean.
#include <numeric>

#include "ui/core/panel.h"
#include "ui/panels/panels.h"

namespace fresco {
namespace {

class TimingPanel : public Panel {
 public:
  const char* Title() const override { return "Timing"; }
  void Draw(UiContext& ui) override {
    if (!BeginPanel(*this)) {
      ImGui::End();
      return;
    }
    const RunnerSnapshot& snap = *ui.snapshot;
    if (snap.stage_ms.empty()) ImGui::TextDisabled("no frame painted yet");
    for (const auto& [stage, ms] : snap.stage_ms) {
      const float mean =
          ms.empty() ? 0.0f : std::accumulate(ms.begin(), ms.end(), 0.0f) / ms.size();
      const std::string label = stage + ": mean " + std::to_string(mean).substr(0, 5) + " ms";
      ImGui::PlotLines(("##" + stage).c_str(), ms.data(), static_cast<int>(ms.size()), 0,
                       label.c_str(), 0.0f, FLT_MAX, ImVec2(ImGui::GetContentRegionAvail().x, 60));
    }
    ImGui::End();
  }
};

}  // namespace

std::unique_ptr<Panel> MakeTimingPanel() { return std::make_unique<TimingPanel>(); }

}  // namespace fresco
