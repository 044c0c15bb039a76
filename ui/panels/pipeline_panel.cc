// Pipeline: play, pause, step, seek, restart; live sources' state and the Record toggle
// (live_status_section.h); and the settings of every stage, edited in the project
// (undoable) and applied by restarting the worker.
#include <algorithm>
#include <cstdio>

#include "ui/core/panel.h"
#include "ui/panels/live_status_section.h"
#include "ui/panels/panels.h"

namespace fresco {
namespace {

class PipelinePanel : public Panel {
 public:
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
    // A file source can go back (repainting from the start up to the previous frame).
    ImGui::BeginDisabled(snap.live.active || snap.frame < 1);
    if (ImGui::Button("<")) PostSeek(ui, snap, std::max(0, ShownFrame(snap) - 1));
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
      ImGui::SetTooltip("step back one frame (repaints from the start)");
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
    if (snap.seek_target >= 0) {  // a seek (back: from the start) under way
      const float done = snap.frame < 0 ? 0.0f
                                        : static_cast<float>(snap.frame + 1) /
                                              static_cast<float>(snap.seek_target + 1);
      ImGui::ProgressBar(done, ImVec2(-1, 0), FrameLabel(snap).c_str());
    }
    ImGui::TextWrapped("%s", snap.status.c_str());
    if (snap.geometry)
      ImGui::Text("%zu base buffers, texel %.4f m, coverage %.1f %%", snap.geometry->groups.size(),
                  snap.geometry->texel_size_m, 100.0 * snap.coverage);
    live_.Draw(ui, snap.live);

    ImGui::Separator();
    ImGui::TextDisabled("Settings (Apply restarts painting)");
    if (!ImGui::IsAnyItemActive()) edit_ = state.project.pipeline;
    // Widgets take what the longest label leaves, so no label runs out of a narrow panel.
    ImGui::PushItemWidth(-ImGui::CalcTextSize("texel size m (0 = auto)").x -
                         ImGui::GetStyle().ItemInnerSpacing.x);
    PipelineOptions& p = edit_;
    bool commit = false;
    auto done = [&] { commit |= ImGui::IsItemDeactivatedAfterEdit(); };
    const char* sampling[] = {"nearest", "bilinear", "area"};
    int mode = static_cast<int>(p.sampling);
    if (ImGui::Combo("sampling", &mode, sampling, 3)) {
      p.sampling = static_cast<SamplingMode>(mode);
      commit = true;
    }
    float texel = static_cast<float>(p.texel_size_m);
    if (ImGui::DragFloat("texel size m (0 = auto)", &texel, 0.0005f, 0.0f, 1.0f, "%.4f"))
      p.texel_size_m = texel;
    done();
    ImGui::DragInt("max buffer texels", &p.max_buffer_texels, 4096, 1, 1 << 26);
    done();
    const char* policies[] = {"latest", "quality"};
    int policy = static_cast<int>(p.update);
    if (ImGui::Combo("update", &policy, policies, 2)) {
      p.update = static_cast<UpdatePolicy>(policy);
      commit = true;
    }
    float slack = static_cast<float>(p.quality_slack);
    if (ImGui::SliderFloat("quality slack", &slack, 0.0f, 1.0f)) p.quality_slack = slack;
    done();
    float weight = static_cast<float>(p.update_weight);
    if (ImGui::SliderFloat("update weight", &weight, 0.01f, 1.0f, "%.2f")) p.update_weight = weight;
    done();
    ImGui::SliderInt("update every", &p.update_every, 1, 60);
    done();
    if (ImGui::Checkbox("occlusion test", &p.occlusion.enabled)) commit = true;
    float rel = static_cast<float>(p.occlusion.tolerance_rel);
    if (ImGui::SliderFloat("tolerance (of depth)", &rel, 0.0f, 0.1f, "%.3f"))
      p.occlusion.tolerance_rel = rel;
    done();
    float abs_m = static_cast<float>(p.occlusion.tolerance_m);
    if (ImGui::SliderFloat("tolerance m", &abs_m, 0.0f, 0.1f, "%.4f"))
      p.occlusion.tolerance_m = abs_m;
    done();
    float angle = static_cast<float>(p.occlusion.max_view_angle_deg);
    if (ImGui::SliderFloat("max view angle deg", &angle, 1.0f, 90.0f, "%.1f"))
      p.occlusion.max_view_angle_deg = angle;
    done();
    ImGui::TextDisabled("refine alignment (§3.5)");
    const char* refine_modes[] = {"off", "paper", "robust"};
    int refine = static_cast<int>(p.refine.mode);
    if (ImGui::Combo("refine", &refine, refine_modes, 3)) {
      p.refine.mode = static_cast<RefineMode>(refine);
      commit = true;
    }
    const char* models[] = {"translation", "similarity", "affine", "homography"};
    int model = static_cast<int>(p.refine.max_model);
    if (ImGui::Combo("most general model", &model, models, 4)) {
      p.refine.max_model = static_cast<RefineModelLimit>(model);
      commit = true;
    }
    ImGui::SliderInt("search texels", &p.refine.search_px, 1, 64);
    done();
    ImGui::SliderInt("window texels", &p.refine.window_px, 1, 32);
    done();
    ImGui::SliderInt("corners", &p.refine.max_corners, 3, 1000);
    done();
    ImGui::SliderInt("refine every N frames", &p.refine.every_n_frames, 1, 30);
    done();
    float dead_band = static_cast<float>(p.refine.min_correction_px);
    if (ImGui::SliderFloat("min correction texels", &dead_band, 0.0f, 2.0f, "%.2f"))
      p.refine.min_correction_px = dead_band;
    done();
    if (ImGui::Checkbox("correct the pose", &p.refine.pose)) commit = true;
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("one pose correction for all buffers");
    if (ImGui::Checkbox("consensus anchoring", &p.refine.anchor)) commit = true;
    float step = static_cast<float>(p.refine.anchor_step_px);
    if (ImGui::SliderFloat("anchor step texels", &step, 0.0f, 2.0f, "%.2f"))
      p.refine.anchor_step_px = step;
    done();
    ImGui::SliderInt("anchor window frames", &p.refine.anchor_window_frames, 0, 1000);
    done();
    ImGui::TextDisabled("background (§3.4)");
    const char* background_modes[] = {"off", "average", "robust"};
    int background = static_cast<int>(p.background.mode);
    if (ImGui::Combo("background", &background, background_modes, 3)) {
      p.background.mode = static_cast<BackgroundMode>(background);
      commit = true;
    }
    ImGui::SliderInt("window frames", &p.background.window_frames, 2, 1000);
    done();
    ImGui::SliderInt("training frames", &p.background.training_frames, 1, 250);
    done();
    if (commit && !(edit_ == state.project.pipeline)) {
      state.BeginEdit();
      state.project.pipeline = edit_;
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
    return report;
  }

 private:
  void PostSeek(UiContext& ui, const RunnerSnapshot& snap, int frame) {
    ui.runner->Seek(frame);
    posted_seek_ = frame;
    posted_version_ = snap.version;
  }

  int seek_ = 0;
  int posted_seek_ = -1;         // a seek posted, not yet in a snapshot
  uint64_t posted_version_ = 0;  // the snapshot version when it was posted
  bool slider_active_ = false;
  float slider_rect_[4] = {0, 0, 0, 0};
  PipelineOptions edit_;
  LiveStatusSection live_;
};

}  // namespace

std::unique_ptr<Panel> MakePipelinePanel() { return std::make_unique<PipelinePanel>(); }

}  // namespace fresco
