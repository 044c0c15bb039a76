// Poses with COLMAP for the operator: run COLMAP on the project's frames in the
// background (steps and elapsed time; cancel), the verification of the project's poses
// against it (per-frame rotation and position disagreement along the sequence and as a
// table, flagged frames red; a click on a row or a point moves the pipeline to that frame),
// and the bootstrapped poses, applied to the project as an undoable edit.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <imgui.h>

#include "ui/core/new_project_bootstrap.h"  // kAppMaxFeatures
#include "ui/panels/panels.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

const float kLabelWidth = 120;  // right of the input fields
const ImU32 kFlaggedColour = IM_COL32(235, 70, 60, 255);
const ImU32 kOkColour = IM_COL32(120, 200, 120, 255);
const ImU32 kMissingColour = IM_COL32(130, 130, 130, 255);
const ImU32 kDriftColour = IM_COL32(240, 180, 60, 255);
const ImU32 kBorderlineColour = IM_COL32(230, 140, 230, 255);

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

// One error along the sequence: a point per frame (red when flagged, pink when borderline,
// amber when following a drift, grey when not judged; grey ticks where COLMAP registered nothing or
// there is no given pose), the threshold dashed, the selected frame and the pipeline's current
// frame as vertical lines. Returns the frame clicked, else -1.
int ErrorPlot(const char* id, const char* label, const PosesSnapshot& snap, bool rotation,
              double scale, const char* unit, int selected, int current_row) {
  const VerifyResult& v = snap.verify;
  const int n = static_cast<int>(v.frames.size());
  const double threshold = (rotation ? v.rotation_threshold_deg : v.position_threshold_m) * scale;
  double top = 2.0 * threshold;
  for (const FrameVerdict& f : v.frames)
    if (f.registered && f.has_given)
      top = std::max(top, (rotation ? f.rotation_error_deg : f.position_error_m) * scale);
  top *= 1.1;
  ImGui::Text("%s (%s); threshold %s, top %s", label, unit, Format("%.3g", threshold).c_str(),
              Format("%.3g", top).c_str());
  const ImVec2 size(ImGui::GetContentRegionAvail().x, 120);
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton(id, size);
  const bool hovered = ImGui::IsItemHovered();
  ImDrawList* draw = ImGui::GetWindowDrawList();
  const float left = p0.x + 6, right = p0.x + size.x - 6, bottom = p0.y + size.y - 4,
              top_y = p0.y + 4;
  draw->AddRectFilled(p0, ImVec2(p0.x + size.x, p0.y + size.y), IM_COL32(25, 25, 30, 255));
  auto x_of = [&](int i) { return n <= 1 ? left : left + (right - left) * i / float(n - 1); };
  auto y_of = [&](double e) {
    return bottom - static_cast<float>(std::min(e / top, 1.0)) * (bottom - top_y);
  };
  // The threshold, dashed.
  const float ty = y_of(threshold);
  for (float x = left; x < right; x += 12)
    draw->AddLine(ImVec2(x, ty), ImVec2(std::min(x + 6, right), ty), IM_COL32(240, 200, 60, 200),
                  1.5f);
  if (selected >= 0 && selected < n)
    draw->AddLine(ImVec2(x_of(selected), top_y), ImVec2(x_of(selected), bottom),
                  IM_COL32(90, 150, 255, 220), 2.0f);
  if (current_row >= 0 && current_row < n)
    draw->AddLine(ImVec2(x_of(current_row), top_y), ImVec2(x_of(current_row), bottom),
                  IM_COL32(255, 255, 255, 90), 1.0f);
  ImVec2 previous;
  bool has_previous = false;
  for (int i = 0; i < n; ++i) {
    const FrameVerdict& f = v.frames[i];
    if (!f.registered || !f.has_given) {
      draw->AddLine(ImVec2(x_of(i), bottom), ImVec2(x_of(i), bottom - 10), kMissingColour, 2.0f);
      has_previous = false;
      continue;
    }
    const ImVec2 p(x_of(i), y_of((rotation ? f.rotation_error_deg : f.position_error_m) * scale));
    if (has_previous) draw->AddLine(previous, p, IM_COL32(180, 180, 190, 160), 1.0f);
    previous = p;
    has_previous = true;
  }
  for (int i = 0; i < n; ++i) {
    const FrameVerdict& f = v.frames[i];
    if (!f.registered || !f.has_given) continue;
    const ImVec2 p(x_of(i), y_of((rotation ? f.rotation_error_deg : f.position_error_m) * scale));
    const ImU32 colour = f.flagged         ? kFlaggedColour
                         : f.weak_support  ? kMissingColour
                         : f.borderline    ? kBorderlineColour
                         : f.follows_drift ? kDriftColour
                                           : kOkColour;
    draw->AddCircleFilled(p, f.flagged ? 4.5f : 3.0f, colour);
  }
  if (n > 0) {  // the sequence's ends
    const std::string first = std::string("frame ") + std::to_string(snap.frame_index.front()),
                      last = std::to_string(snap.frame_index.back());
    draw->AddText(ImVec2(left, top_y), IM_COL32(150, 150, 160, 255), first.c_str());
    draw->AddText(ImVec2(right - ImGui::CalcTextSize(last.c_str()).x, top_y),
                  IM_COL32(150, 150, 160, 255), last.c_str());
  }
  if (!hovered || n == 0) return -1;
  const float mx = ImGui::GetIO().MousePos.x;
  const int i = std::clamp(
      static_cast<int>(std::lround((mx - left) / std::max(1.0f, right - left) * (n - 1))), 0,
      n - 1);
  const FrameVerdict& f = v.frames[i];
  if (!f.registered)
    ImGui::SetTooltip("%s: not registered by COLMAP", f.name.c_str());
  else if (!f.has_given)
    ImGui::SetTooltip("%s: no given pose", f.name.c_str());
  else
    ImGui::SetTooltip("%s: %.3f deg, %.4f m, %s (click to go there)", f.name.c_str(),
                      f.rotation_error_deg, f.position_error_m, VerdictText(f, v).c_str());
  return ImGui::IsItemClicked() ? i : -1;
}

class PosesPanel : public Panel {
 public:
  PosesPanel() { open = false; }
  const char* Title() const override { return kPosesPanelTitle; }
  std::map<std::string, std::string> Report() const override { return report_; }

  void Draw(UiContext& ui) override {
    if (!BeginOverlayPanel(*this, ui.poses != nullptr, "COLMAP worker")) return;
    const auto snap = ui.poses->Snapshot();
    if (snap->has_request && !taken_) TakeInputs(snap->request);
    if (ImGui::BeginTable("poses", 2, ImGuiTableFlags_Resizable | ImGuiTableFlags_BordersInnerV)) {
      ImGui::TableSetupColumn("controls", ImGuiTableColumnFlags_WidthStretch, 0.3f);
      ImGui::TableSetupColumn("results", ImGuiTableColumnFlags_WidthStretch, 0.7f);
      ImGui::TableNextRow();
      ImGui::TableSetColumnIndex(0);
      DrawControls(ui, *snap);
      ImGui::TableSetColumnIndex(1);
      DrawResults(ui, *snap);
      ImGui::EndTable();
    }
    UpdateReport(ui, *snap);
    ImGui::End();
  }

 private:
  // The inputs of a run started elsewhere (`fresco gui --poses`), once.
  void TakeInputs(const PosesRequest& r) {
    taken_ = true;
    std::snprintf(out_dir_, sizeof(out_dir_), "%s", r.out_dir.c_str());
    std::snprintf(model_, sizeof(model_), "%s", r.colmap.existing_model.c_str());
    std::snprintf(control_, sizeof(control_), "%s", r.control_points_file.c_str());
    every_ = r.colmap.every_n_frames;
    max_frames_ = r.colmap.max_frames;
    max_image_size_ = r.colmap.colmap.max_image_size;
    if (r.colmap.colmap.max_num_features > 0) max_features_ = r.colmap.colmap.max_num_features;
    matcher_ = static_cast<int>(r.colmap.colmap.matcher);
    keyframe_step_pct_ = static_cast<float>(100 * r.colmap.keyframe_step_rel);
    keyframe_turn_deg_ = static_cast<float>(r.colmap.keyframe_rotation_deg);
    rotation_threshold_ = static_cast<float>(r.verify.rotation_threshold_deg);
    position_threshold_pct_ = static_cast<float>(100 * r.verify.position_threshold_rel);
  }

  void DrawControls(UiContext& ui, const PosesSnapshot& snap) {
    if (!ui.state || !ui.state->has_project) {
      ImGui::TextWrapped("Open a project first: COLMAP runs on its frames, with its camera.");
      return;
    }
    const Project& project = ui.state->project;
    if (out_dir_[0] == 0)
      std::snprintf(out_dir_, sizeof(out_dir_), "%s",
                    (fs::path(project.file_path).parent_path() / "colmap-poses").c_str());
    ImGui::TextWrapped("Project: %s", project.file_path.c_str());
    struct Text {
      const char* label;
      char* buffer;
      size_t size;
      const char* tip;
    };
    for (const Text& t :
         {Text{"output folder", out_dir_, sizeof(out_dir_),
               "COLMAP's workspace (colmap/: commands, logs), verify.json and .png,\n"
               "the bootstrapped poses (sparse/) and project.json"},
          Text{"earlier model", model_, sizeof(model_),
               "optional: a COLMAP text model of an earlier run (OUT/colmap/sparse_txt/0)\n"
               "to use instead of running COLMAP"},
          Text{"control points", control_, sizeof(control_),
               "optional: align the bootstrap with >= 3 known points instead of the\n"
               "given poses; one per line: NAME X Y Z IMAGE U V [IMAGE U V ...]"}}) {
      ImGui::SetNextItemWidth(-kLabelWidth);
      ImGui::InputText(t.label, t.buffer, t.size);
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", t.tip);
    }
    struct Number {
      const char* label;
      int* value;
      int step, min;
    };
    for (const Number& n :
         {Number{"every Nth frame", &every_, 1, 1}, Number{"max frames", &max_frames_, 1, 0},
          Number{"max image size", &max_image_size_, 100, 0},
          Number{"max features", &max_features_, 500, 0}}) {
      ImGui::SetNextItemWidth(-kLabelWidth);
      ImGui::InputInt(n.label, n.value, n.step);
      if (n.min == 0 && ImGui::IsItemHovered()) ImGui::SetTooltip("0 = all (COLMAP's default)");
      *n.value = std::max(n.min, *n.value);
    }
    ImGui::SetNextItemWidth(-kLabelWidth);
    ImGui::Combo("matcher", &matcher_, "auto\0exhaustive\0sequential\0");
    ImGui::SetNextItemWidth(-kLabelWidth);
    ImGui::InputFloat("keyframe step %", &keyframe_step_pct_, 0.1f, 0, "%.2f");
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip(
          "in a sequence, a frame goes to COLMAP when its given pose moved this\n"
          "%% of the scene size or turned the angle below since the last one\n"
          "(0 and 0: every frame)");
    keyframe_step_pct_ = std::max(0.0f, keyframe_step_pct_);
    ImGui::SetNextItemWidth(-kLabelWidth);
    ImGui::InputFloat("keyframe turn, deg", &keyframe_turn_deg_, 0.5f, 0, "%.1f");
    keyframe_turn_deg_ = std::max(0.0f, keyframe_turn_deg_);
    ImGui::SetNextItemWidth(-kLabelWidth);
    ImGui::InputFloat("flag above, deg", &rotation_threshold_, 0.1f, 0, "%.2f");
    rotation_threshold_ = std::max(0.0f, rotation_threshold_);
    ImGui::SetNextItemWidth(-kLabelWidth);
    ImGui::InputFloat("or % of scene", &position_threshold_pct_, 0.1f, 0, "%.2f");
    position_threshold_pct_ = std::max(0.0f, position_threshold_pct_);

    if (!snap.busy) {
      if (ImGui::Button("Run COLMAP")) StartRun(ui);
    } else if (ImGui::Button("Cancel")) {
      ui.poses->Cancel();
    }
    ColmapProgressBar(snap);
    if (snap.status.rfind("error", 0) == 0)
      ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", snap.status.c_str());
    else
      ImGui::TextWrapped("%s",
                         snap.status.empty()
                             ? "Run COLMAP to verify the project's poses and bootstrap new ones."
                             : snap.status.c_str());
    if (snap.reconstructed) {
      ImGui::Separator();
      if (!snap.matcher.empty())
        ImGui::TextWrapped(
            "%d of %d frames reconstructed as keyframes, the others registered "
            "to them; %s matching",
            snap.keyframes, snap.frames_offered, snap.matcher.c_str());
      for (const auto& [step, seconds] : snap.step_seconds)
        ImGui::Text("  %-20s %6.1f s", step.c_str(), seconds);
    }
    if (!snap.verify_error.empty())
      ImGui::TextColored(ImVec4(1, 0.6f, 0.3f, 1), "verify: %s", snap.verify_error.c_str());
    DrawBootstrap(ui, snap);
  }

  void StartRun(UiContext& ui) {
    PosesRequest r;
    r.project = ui.state->project;
    r.out_dir = out_dir_;
    r.colmap.existing_model = model_;
    r.control_points_file = control_;
    r.colmap.every_n_frames = every_;
    r.colmap.max_frames = max_frames_;
    r.colmap.colmap.max_image_size = max_image_size_;
    r.colmap.colmap.max_num_features = max_features_;
    r.colmap.colmap.matcher = static_cast<ColmapMatcher>(matcher_);
    r.colmap.keyframe_step_rel = keyframe_step_pct_ / 100.0;
    r.colmap.keyframe_rotation_deg = keyframe_turn_deg_;
    r.verify.rotation_threshold_deg = rotation_threshold_;
    r.verify.position_threshold_rel = position_threshold_pct_ / 100.0;
    if (Status s = r.verify.Check(); !s.ok()) {
      ui.state->message = std::string("error: ") + s.message();
      return;
    }
    selected_ = -1;
    taken_ = true;
    apply_anyway_ = false;
    ui.poses->Run(r);
  }

  void DrawBootstrap(UiContext& ui, const PosesSnapshot& snap) {
    if (!snap.reconstructed) return;
    ImGui::Separator();
    ImGui::TextUnformatted("Bootstrapped poses");
    if (!snap.bootstrapped) {
      ImGui::TextColored(ImVec4(1, 0.6f, 0.3f, 1), "%s", snap.bootstrap_error.c_str());
      return;
    }
    if (snap.aligned_with == "given_poses")
      ImGui::TextWrapped("%d frames posed; aligned to the given poses (%d of %d support the fit)",
                         snap.registered, snap.bootstrap_inliers, snap.bootstrap_compared);
    else
      ImGui::TextWrapped("%d frames posed; aligned to the control points", snap.registered);
    ImGui::TextWrapped("%s", snap.bootstrap_poses.c_str());
    // Which are better, on the frames both have; worse poses need a deliberate click.
    const PosesComparison& c = snap.bootstrap_comparison;
    const bool doubtful = c.better == "given" || c.better == "unknown";
    if (doubtful) ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.6f, 0.3f, 1));
    ImGui::TextWrapped("%s", c.summary.c_str());
    if (doubtful) ImGui::PopStyleColor();
    const bool applied = ui.state->has_project && ui.state->project.poses == snap.bootstrap_poses;
    if (doubtful && !applied) ImGui::Checkbox("apply anyway", &apply_anyway_);
    ImGui::BeginDisabled(applied || snap.busy || (doubtful && !apply_anyway_));
    if (ImGui::Button(applied    ? "Applied (Ctrl+Z undoes)"
                      : doubtful ? "Apply to the project (likely worse)"
                                 : "Apply to the project")) {
      if (Status s = ApplyBootstrappedPoses(snap, ui.state); !s.ok()) {
        ui.state->message = std::string("error: ") + s.message();
      } else {
        ApplyProject(ui);  // repaint with the new poses
      }
    }
    ImGui::EndDisabled();
  }

  void DrawResults(UiContext& ui, const PosesSnapshot& snap) {
    if (!snap.verified) {
      ImGui::TextDisabled("The verification appears here after a run.");
      return;
    }
    const VerifyResult& v = snap.verify;
    ImGui::Text("%d frames: %d registered by COLMAP, %d compared, %d flagged, %d borderline",
                snap.frames, v.registered, v.compared, v.flagged, v.borderline);
    ImGui::TextWrapped("%s", VerifyAgreementText(v).c_str());
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.75f, 0.3f, 1));
    for (const std::string& note : VerifyNotes(v)) ImGui::TextWrapped("%s", note.c_str());
    ImGui::PopStyleColor();
    // The pipeline's frame, as a row.
    int current_row = -1;
    if (ui.snapshot)
      for (size_t i = 0; i < snap.frame_index.size(); ++i)
        if (snap.frame_index[i] == ui.snapshot->frame) current_row = static_cast<int>(i);
    int go = ErrorPlot("##rotation", "Rotation disagreement", snap, true, 1.0, "deg", selected_,
                       current_row);
    const int go_position =
        ErrorPlot("##position", "Position disagreement", snap, false,
                  100.0 / std::max(1e-12, v.scene_size_m), "% of scene", selected_, current_row);
    if (go < 0) go = go_position;
    // Flagged frames, one click away.
    std::vector<int> flagged;
    for (int i = 0; i < static_cast<int>(v.frames.size()); ++i)
      if (v.frames[i].flagged) flagged.push_back(i);
    ImGui::BeginDisabled(flagged.empty());
    if (ImGui::Button("previous flagged")) {
      auto it = std::lower_bound(flagged.begin(), flagged.end(), selected_);
      go = it == flagged.begin() ? flagged.back() : *std::prev(it);
    }
    ImGui::SameLine();
    if (ImGui::Button("next flagged")) {
      auto it = std::upper_bound(flagged.begin(), flagged.end(), selected_);
      go = it == flagged.end() ? flagged.front() : *it;
    }
    next_button_[0] = ImGui::GetItemRectMin().x, next_button_[1] = ImGui::GetItemRectMin().y;
    next_button_[2] = ImGui::GetItemRectMax().x, next_button_[3] = ImGui::GetItemRectMax().y;
    ImGui::EndDisabled();
    ImGui::SameLine();
    ImGui::Checkbox("flagged only", &flagged_only_);
    if (int row = DrawTable(snap); row >= 0) go = row;
    if (go >= 0) Go(ui, snap, go);
  }

  // The verification table; returns the row clicked, else -1.
  int DrawTable(const PosesSnapshot& snap) {
    const VerifyResult& v = snap.verify;
    const ImGuiTableFlags flags = ImGuiTableFlags_RowBg | ImGuiTableFlags_Borders |
                                  ImGuiTableFlags_ScrollY | ImGuiTableFlags_SizingStretchProp;
    if (!ImGui::BeginTable("verify", 6, flags, ImVec2(0, ImGui::GetContentRegionAvail().y)))
      return -1;
    ImGui::TableSetupScrollFreeze(0, 1);
    for (const char* h : {"frame", "image", "rotation deg", "position m", "% scene", "verdict"})
      ImGui::TableSetupColumn(h);
    ImGui::TableHeadersRow();
    int clicked = -1;
    for (int i = 0; i < static_cast<int>(v.frames.size()); ++i) {
      const FrameVerdict& f = v.frames[i];
      if (flagged_only_ && !f.flagged) continue;
      ImGui::TableNextRow();
      if (f.flagged) ImGui::TableSetBgColor(ImGuiTableBgTarget_RowBg0, IM_COL32(120, 30, 30, 255));
      ImGui::TableSetColumnIndex(0);
      ImGui::PushID(i);
      if (ImGui::Selectable(std::to_string(snap.frame_index[i]).c_str(), selected_ == i,
                            ImGuiSelectableFlags_SpanAllColumns))
        clicked = i;
      if (scroll_to_selected_ && selected_ == i) {
        ImGui::SetScrollHereY(0.5f);
        scroll_to_selected_ = false;
      }
      ImGui::PopID();
      ImGui::TableSetColumnIndex(1);
      ImGui::TextUnformatted(f.name.c_str());
      const bool both = f.registered && f.has_given;
      ImGui::TableSetColumnIndex(2);
      if (both) ImGui::Text("%.3f", f.rotation_error_deg);
      ImGui::TableSetColumnIndex(3);
      if (both) ImGui::Text("%.4f", f.position_error_m);
      ImGui::TableSetColumnIndex(4);
      if (both) ImGui::Text("%.2f", 100 * f.position_error_m / std::max(1e-12, v.scene_size_m));
      ImGui::TableSetColumnIndex(5);
      const std::string verdict = VerdictText(f, v);
      if (!both || f.weak_support)
        ImGui::TextDisabled("%s", verdict.c_str());
      else if (f.flagged)
        ImGui::TextColored(ImVec4(1, 0.75f, 0.7f, 1), "%s", verdict.c_str());
      else if (f.borderline)
        ImGui::TextColored(ImVec4(0.95f, 0.6f, 0.95f, 1), "%s", verdict.c_str());
      else if (f.follows_drift)
        ImGui::TextColored(ImVec4(1, 0.85f, 0.5f, 1), "%s", verdict.c_str());
      else
        ImGui::TextUnformatted(verdict.c_str());
    }
    ImGui::EndTable();
    return clicked;
  }

  // Selects the row and moves the pipeline to its frame (as the misalignment panel does).
  void Go(UiContext& ui, const PosesSnapshot& snap, int row) {
    selected_ = row;
    scroll_to_selected_ = true;
    if (ui.runner && row < static_cast<int>(snap.frame_index.size()))
      ui.runner->Seek(snap.frame_index[row]);
  }

  void UpdateReport(const UiContext& ui, const PosesSnapshot& snap) {
    report_ = {{"status", snap.status}, {"max_features", std::to_string(max_features_)}};
    if (snap.verified) {
      std::string flagged;
      for (size_t i = 0; i < snap.verify.frames.size(); ++i)
        if (snap.verify.frames[i].flagged)
          flagged += std::string(flagged.empty() ? "" : ",") + std::to_string(snap.frame_index[i]);
      report_["frames"] = std::to_string(snap.frames);
      report_["registered"] = std::to_string(snap.verify.registered);
      report_["flagged"] = std::to_string(snap.verify.flagged);
      report_["flagged_frames"] = flagged;
    }
    report_["bootstrapped"] = snap.bootstrapped ? "true" : "false";
    if (snap.bootstrapped) report_["bootstrap_better"] = snap.bootstrap_comparison.better;
    if (snap.verified) {
      report_["agreement"] = VerifyAgreementText(snap.verify);
      report_["centres_collinear"] = snap.verify.centres.collinear ? "true" : "false";
    }
    report_["applied"] = snap.bootstrapped && ui.state && ui.state->has_project &&
                                 ui.state->project.poses == snap.bootstrap_poses
                             ? "true"
                             : "false";
    if (selected_ >= 0 && selected_ < static_cast<int>(snap.frame_index.size()))
      report_["selected_frame"] = std::to_string(snap.frame_index[selected_]);
    if (snap.verified) {  // where "next flagged" is (screen pixels: x0 y0 x1 y1), for tests
      char rect[96];
      std::snprintf(rect, sizeof(rect), "%.0f %.0f %.0f %.0f", next_button_[0], next_button_[1],
                    next_button_[2], next_button_[3]);
      report_["next_flagged_button"] = rect;
    }
  }

  char out_dir_[1024] = "";
  char model_[1024] = "";
  char control_[1024] = "";
  int every_ = 1, max_frames_ = 0, max_image_size_ = 0, max_features_ = kAppMaxFeatures,
      matcher_ = 0;
  float rotation_threshold_ = 0.5f, position_threshold_pct_ = 1.0f;
  float keyframe_step_pct_ = 0.5f, keyframe_turn_deg_ = 2.0f;
  bool flagged_only_ = false, scroll_to_selected_ = false, apply_anyway_ = false;
  int selected_ = -1;
  float next_button_[4] = {0, 0, 0, 0};
  bool taken_ = false;
  std::map<std::string, std::string> report_;
};

}  // namespace

std::unique_ptr<Panel> MakePosesPanel() { return std::make_unique<PosesPanel>(); }

}  // namespace fresco
