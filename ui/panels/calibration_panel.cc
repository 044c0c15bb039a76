// Calibration for the operator: the folder, board and lens model; Detect, Solve and
// Save (beside the project by default) and Attach to project (checked against the project's
// frames, then confirmed); the "enough data yet?" light
// that follows the detections image by image (never green for a folder that mixes cameras);
// the images (used, rejected with the reason, or excluded by their checkbox); the selected
// image with its detections; the coverage
// map; per-image residuals, the models tried and the one chosen; the warnings.
#include <algorithm>
#include <chrono>
#include <cstdio>

#include <imgui_internal.h>  // PushOverrideID
#include <opencv2/imgcodecs.hpp>

#include "calib/pictures.h"
#include "pipeline/core/image_io.h"
#include "ui/core/camera_attach.h"
#include "ui/core/job_estimate.h"
#include "ui/panels/panels.h"
#include "ui/panels/path_field.h"

namespace fresco {
namespace {

using calib::DataReadiness;

constexpr const char* kAttachPopup = "Attach camera?";
constexpr float kControlsShare = 0.27f;  // of the panel's width, in three columns

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

void TrafficLight(const DataReadiness& r) {
  static const ImVec4 kColours[] = {ImVec4(0.9f, 0.2f, 0.2f, 1), ImVec4(0.95f, 0.75f, 0.1f, 1),
                                    ImVec4(0.2f, 0.8f, 0.3f, 1)};
  static const char* kWords[] = {"NOT ENOUGH DATA", "USABLE, WITH DOUBTS", "ENOUGH DATA"};
  const int level = static_cast<int>(r.level);
  ImDrawList* draw = ImGui::GetWindowDrawList();
  const ImVec2 p = ImGui::GetCursorScreenPos();
  const float radius = ImGui::GetTextLineHeight() * 0.9f;
  for (int i = 0; i < 3; ++i) {  // red, yellow, green: the lit one bright
    ImVec4 c = kColours[i];
    if (i != level) c = ImVec4(c.x * 0.25f, c.y * 0.25f, c.z * 0.25f, 1);
    draw->AddCircleFilled(ImVec2(p.x + radius + i * 2.3f * radius, p.y + radius), radius,
                          ImGui::ColorConvertFloat4ToU32(c));
  }
  ImGui::Dummy(ImVec2(7 * radius, 2 * radius));
  // The words beside the lights where they fit, else below them (wrapped at spaces there, in
  // a panel narrower still): never cut at the panel's edge.
  const float words = ImGui::CalcTextSize(kWords[level]).x;
  const float beside =
      ImGui::GetContentRegionAvail().x - 7 * radius - ImGui::GetStyle().ItemSpacing.x;
  if (words <= beside) ImGui::SameLine();
  ImGui::PushStyleColor(ImGuiCol_Text, kColours[level]);
  ImGui::TextWrapped("%s", kWords[level]);
  ImGui::PopStyleColor();
  ImGui::Text("%d views (min %d, want %d+)", r.views, calib::kMinViews, calib::kFewViews);
  ImGui::Text("coverage %.0f %% (want %.0f %%), tilt %s (want %.0f)", 100 * r.coverage_fraction,
              100 * calib::kMinCoverage,
              r.max_tilt_deg < 0 ? "?" : Format("%.0f deg", r.max_tilt_deg).c_str(),
              calib::kMinTiltDeg);
  for (const std::string& reason : r.reasons) {  // wrapped: a mixed-camera reason is long
    ImGui::Bullet();
    ImGui::TextWrapped("%s", reason.c_str());
  }
}

class CalibrationPanel : public Panel {
 public:
  CalibrationPanel() { open = false; }
  const char* Title() const override { return kCalibrationPanelTitle; }

  std::map<std::string, std::string> Report() const override { return report_; }

  void Draw(UiContext& ui) override {
    if (!BeginOverlayPanel(*this, ui.calibration != nullptr, "calibration worker")) return;
    const auto snap = ui.calibration->Snapshot();
    if (snap->has_request && folder_.empty()) TakeInputs(snap->request);
    // A panel too narrow for three columns (the controls' would be under 15 characters wide)
    // shows them one under another instead of squeezing their words a few letters a line.
    if (ImGui::GetContentRegionAvail().x * kControlsShare < 15 * ImGui::GetFontSize()) {
      DrawControls(ui, *snap);
      ImGui::Separator();
      DrawPictures(ui, *snap);
      ImGui::Separator();
      DrawResults(ui, *snap);
    } else if (ImGui::BeginTable("calibration", 3,
                                 ImGuiTableFlags_Resizable | ImGuiTableFlags_BordersInnerV)) {
      ImGui::TableSetupColumn("controls", ImGuiTableColumnFlags_WidthStretch, kControlsShare);
      ImGui::TableSetupColumn("pictures", ImGuiTableColumnFlags_WidthStretch, 0.35f);
      ImGui::TableSetupColumn("results", ImGuiTableColumnFlags_WidthStretch, 0.38f);
      ImGui::TableNextRow();
      ImGui::TableSetColumnIndex(0);
      // The controls' IDs as at the window's root, whatever the table pushed (the tests and
      // keyboard navigation name them "##folder", "Attach to project...").
      ImGui::PushOverrideID(ImGui::GetCurrentWindow()->ID);
      DrawControls(ui, *snap);
      ImGui::PopID();
      ImGui::TableSetColumnIndex(1);
      DrawPictures(ui, *snap);
      ImGui::TableSetColumnIndex(2);
      DrawResults(ui, *snap);
      ImGui::EndTable();
    }
    UpdateReport(*snap);
    ImGui::End();
  }

 private:
  void TakeInputs(const calib::CalibrateRequest& request) {
    folder_ = request.images_dir;
    std::snprintf(board_, sizeof(board_), "%s", request.board.text.c_str());
    const auto& names = calib::LensModelShortNames();
    const auto it = std::find(names.begin(), names.end(), request.model);
    model_ = it == names.end() ? 0 : 1 + static_cast<int>(it - names.begin());
  }

  std::string ModelName() const {
    return model_ == 0 ? "auto" : calib::LensModelShortNames()[model_ - 1];
  }

  void DrawControls(UiContext& ui, const CalibrationSnapshot& snap) {
    PathField("Folder", "##folder", "the calibration pictures' folder/", &folder_,
              {.extensions = {},
               .folder_of_images = true,
               .last_folder = ui.state ? &ui.state->last_folder : nullptr});
    ImGui::SetNextItemWidth(-60);
    ImGui::InputText("board", board_, sizeof(board_));
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("chessboard:COLSxROWS:SQUARE_M or aprilgrid:COLSxROWS:TAG_M:SPACING");
    ImGui::SetNextItemWidth(-60);
    const std::string current = ModelName();
    if (ImGui::BeginCombo("model", current.c_str())) {
      for (int i = 0; i <= static_cast<int>(calib::LensModelShortNames().size()); ++i) {
        const std::string name = i == 0 ? "auto" : calib::LensModelShortNames()[i - 1];
        if (ImGui::Selectable(name.c_str(), i == model_)) model_ = i;
      }
      ImGui::EndCombo();
    }
    if (ImGui::Button("Detect")) StartDetect(ui);
    ImGui::SameLine();
    ImGui::BeginDisabled(snap.busy || static_cast<int>(snap.run.views.size()) < calib::kMinViews);
    if (ImGui::Button("Solve")) ui.calibration->Solve();
    ImGui::EndDisabled();
    ImGui::SameLine();
    ImGui::BeginDisabled(snap.busy || !snap.solved);
    if (ImGui::Button("Save")) {
      const std::string beside =
          ui.state->has_project ? ui.state->project.file_path : std::string();
      std::snprintf(save_path_, sizeof(save_path_), "%s",
                    DefaultCameraModelPath(folder_, beside).c_str());
      ImGui::OpenPopup("Save calibration");
    }
    ImGui::EndDisabled();
    if (snap.busy) {
      ImGui::SameLine();
      if (ImGui::Button("Cancel")) ui.calibration->Cancel();
    }
    DrawSavePopup(ui);
    DrawAttach(ui, snap);
    if (snap.solving && snap.solves_total > 0) {
      const double elapsed_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - snap.solve_started)
              .count();
      const float fraction = snap.solves_done / float(snap.solves_total);
      const std::string text = std::to_string(snap.solves_done) + "/" +
                               std::to_string(snap.solves_total) + " fits, " +
                               ElapsedAndRemainingText(elapsed_s, fraction);
      ProgressBarWithText(fraction, text);
    }
    if (!snap.images.empty())
      ImGui::ProgressBar(
          snap.images_done / float(snap.images.size()), ImVec2(-1, 0),
          (std::to_string(snap.images_done) + "/" + std::to_string(snap.images.size()) + " images")
              .c_str());
    if (snap.status.rfind("error", 0) == 0)
      ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", snap.status.c_str());
    else
      ImGui::TextWrapped("%s", snap.status.empty() ? "choose a folder and a board, then Detect"
                                                   : snap.status.c_str());
    ImGui::Separator();
    ImGui::TextUnformatted("Enough data yet?");
    TrafficLight(snap.readiness);
    if (!snap.run.camera_doubts.empty())
      ImGui::TextColored(
          ImVec4(1, 0.35f, 0.3f, 1),
          "NOT ONE CAMERA? See the reasons above; untick the other camera's images.");
    ImGui::Separator();
    DrawImageList(ui, snap);
  }

  void StartDetect(UiContext& ui) {
    calib::CalibrateRequest request;
    request.images_dir = folder_;
    request.model = ModelName();
    if (Status s = calib::ParseBoardSpec(board_, "board", &request.board); !s.ok()) {
      ui.state->message = "error: " + s.message();
      return;
    }
    selected_ = -1;
    ui.calibration->Detect(request);
  }

  void DrawSavePopup(UiContext& ui) {
    if (!ImGui::BeginPopup("Save calibration")) return;
    ImGui::SetNextItemWidth(400);
    ImGui::InputText(".cameramodel", save_path_, sizeof(save_path_));
    if (ImGui::Button("Save")) {
      ui.calibration->Save(save_path_);
      ImGui::CloseCurrentPopup();
    }
    ImGui::EndPopup();
  }

  // "Attach to project": a .cameramodel (the one just saved, or any other) becomes the open
  // project's camera. Nothing changes until the checks pass (the camera's size against the
  // project's frames, the lens's plausibility) and the user confirms that the painting
  // starts over; Ctrl+Z restores the previous camera.
  void DrawAttach(UiContext& ui, const CalibrationSnapshot& snap) {
    if (!ui.state || !ui.state->has_project) return;
    if (snap.saved_path != attach_saved_) {  // a new Save: that file, checked afresh
      attach_saved_ = snap.saved_path;
      attach_path_ = snap.saved_path;
      attach_error_.clear();
    }
    ImGui::Separator();
    if (PathField("Attach", "##attach", ".cameramodel (Save writes one)", &attach_path_,
                  {.extensions = {".cameramodel"}, .last_folder = &ui.state->last_folder}))
      attach_error_.clear();
    const bool v2 = ui.state->project.fresco_version >= 2;
    if (v2) {
      ImGui::SetNextItemWidth(80);
      ImGui::InputInt("stream", &attach_stream_);
      ImGui::SameLine();
    }
    ImGui::BeginDisabled(attach_path_.empty());
    if (ImGui::Button("Attach to project...")) {
      const Status s =
          CheckCameraForProject(attach_path_, v2 ? attach_stream_ : 0, ui.state->project, &check_);
      if (!s.ok()) {
        attach_error_ = s.message();
        ui.state->message = "error: " + s.message();
      } else {
        attach_error_.clear();
        ImGui::OpenPopup(kAttachPopup);
      }
    }
    ImGui::EndDisabled();
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
      ImGui::SetTooltip(
          "checks the camera against the project's frames, then asks before the "
          "project's %s changes (Ctrl+Z undoes)",
          v2 ? "streams[i].camera" : "camera");
    if (!attach_error_.empty()) {
      ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.4f, 0.4f, 1));
      ImGui::TextWrapped("%s", attach_error_.c_str());
      ImGui::PopStyleColor();
    }
    DrawAttachConfirm(ui, v2 ? attach_stream_ : 0);
  }

  // The confirmation: what the camera is, and that the painting starts over.
  void DrawAttachConfirm(UiContext& ui, int stream) {
    ImGui::SetNextWindowSize(ImVec2(ImGui::GetFontSize() * 34, 0), ImGuiCond_Appearing);
    if (!ImGui::BeginPopupModal(kAttachPopup, nullptr)) return;
    ImGui::TextWrapped("%s: %s.", attach_path_.c_str(), check_.summary.c_str());
    const int painted = ui.snapshot ? static_cast<int>(ui.snapshot->frames_painted.size()) : 0;
    ImGui::TextWrapped(
        "Attaching makes it the project's %s and paints again through it: the %d frame%s "
        "painted so far %s painted again. Ctrl+Z returns to the previous camera.",
        ui.state->project.StreamKey(stream, "camera").c_str(), painted, painted == 1 ? "" : "s",
        painted == 1 ? "is" : "are");
    if (ImGui::Button("Attach and repaint")) {
      if (Status s = AttachCameraToProject(attach_path_, stream, ui.state); !s.ok())
        ui.state->message = "error: " + s.message();
      else
        ApplyProject(ui);  // repaint through the new camera
      ImGui::CloseCurrentPopup();
    }
    ImGui::SameLine();
    if (ImGui::Button("Cancel") || ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape))) {
      ui.state->message = "camera not attached; the painting goes on as it was";
      ImGui::CloseCurrentPopup();
    }
    ImGui::EndPopup();
  }

  void DrawImageList(UiContext& ui, const CalibrationSnapshot& snap) {
    ImGui::Text("Images (%zu used, %zu rejected, %zu excluded)", snap.run.views.size(),
                snap.run.rejected.size(), snap.run.excluded.size());
    if (!ImGui::BeginChild("images", ImVec2(0, 0), true)) {
      ImGui::EndChild();
      return;
    }
    for (int i = 0; i < static_cast<int>(snap.images.size()); ++i) {
      const CalibrationImage& image = snap.images[i];
      bool use = !image.excluded;  // the operator's per-image choice
      ImGui::BeginDisabled(snap.busy);
      if (ImGui::Checkbox(("##use" + std::to_string(i)).c_str(), &use))
        ui.calibration->Exclude(image.name, !use);
      ImGui::EndDisabled();
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("use this image (untick to exclude it)");
      ImGui::SameLine();
      const ImVec4 colour = !image.done || image.excluded ? ImVec4(0.6f, 0.6f, 0.6f, 1)
                            : image.used                  ? ImVec4(0.5f, 0.9f, 0.5f, 1)
                                                          : ImVec4(1, 0.5f, 0.4f, 1);
      std::string label = image.name + (image.excluded ? "  excluded"
                                        : !image.done  ? "  ..."
                                        : image.used   ? "  used"
                                                       : "  rejected");
      if (image.used)
        label += " (" + std::to_string(snap.run.views[image.view].corners.size()) + " corners)";
      ImGui::PushStyleColor(ImGuiCol_Text, colour);
      if (ImGui::Selectable(label.c_str(), selected_ == i)) selected_ = i;
      ImGui::PopStyleColor();
      if (!image.reason.empty()) ImGui::TextDisabled("    %s", image.reason.c_str());
    }
    ImGui::EndChild();
  }

  // The selected image (default: the first used one) with its detections, drawn once per
  // selection and snapshot.
  void DrawPictures(UiContext& ui, const CalibrationSnapshot& snap) {
    int shown = selected_;
    if (shown < 0)
      for (int i = 0; i < static_cast<int>(snap.images.size()) && shown < 0; ++i)
        if (snap.images[i].used) shown = i;
    if (shown >= 0 && shown < static_cast<int>(snap.images.size())) {
      const CalibrationImage& image = snap.images[shown];
      if (shown != drawn_image_ || snap.version != drawn_version_) {
        cv::Mat pixels;
        if (!ReadImage(image.path, &pixels, cv::IMREAD_COLOR).ok()) pixels.release();
        const calib::ViewFit* fit = nullptr;
        if (snap.solved && image.used) fit = &snap.run.Chosen().fit.views[image.view];
        detections_ = pixels.empty() || !image.used
                          ? pixels
                          : calib::DrawDetections(pixels, snap.run.views[image.view].corners, fit);
        drawn_image_ = shown;
        drawn_version_ = snap.version;
      }
      ImGui::Text("%s: %s", image.name.c_str(),
                  image.used             ? "detections"
                  : image.reason.empty() ? "not detected yet"
                                         : image.reason.c_str());
      ShowImage(ui, "calibration image", detections_, drawn_version_ * 1000 + shown);
    } else {
      ImGui::TextDisabled("(no image with a board yet)");
    }
    ImGui::Separator();
    ImGui::TextUnformatted("Coverage of the imager (all detections)");
    ShowImage(ui, "calibration coverage", snap.coverage_picture, snap.version);
  }

  void DrawResults(UiContext& ui, const CalibrationSnapshot& snap) {
    if (!snap.solved) {
      ImGui::TextDisabled("Residuals and models appear after Solve.");
    } else {
      DrawResiduals(snap);
      ImGui::Separator();
      DrawModels(snap);
    }
    ImGui::Separator();
    ImGui::Text("Warnings (%zu)", snap.run.warnings.size());
    for (const std::string& w : snap.run.warnings) {
      ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.8f, 0.3f, 1));
      ImGui::TextWrapped("- %s", w.c_str());
      ImGui::PopStyleColor();
    }
    if (snap.solved) {
      ImGui::Separator();
      ImGui::TextUnformatted("Residual vectors (calib solve's residuals picture)");
      ShowImage(ui, "calibration residuals", snap.residuals_picture, snap.version);
      const calib::UncertaintyMap& u = snap.run.uncertainty;
      ImGui::Separator();
      ImGui::Text(
          "Projection uncertainty at %.2f m: centre %.3f px, where observed %.3f px, max %.3f px",
          u.range_m, u.centre_px, u.median_observed_px, u.max_px);
      if (!snap.uncertainty_picture.empty())
        ShowImage(ui, "calibration uncertainty", snap.uncertainty_picture, snap.version);
    }
  }

  void DrawResiduals(const CalibrationSnapshot& snap) {
    const calib::SolveResult& fit = snap.run.Chosen().fit;
    std::vector<float> rms;
    float max_rms = 0;
    for (const calib::ViewFit& v : fit.views) {
      rms.push_back(static_cast<float>(v.rms_px));
      max_rms = std::max(max_rms, rms.back());
    }
    ImGui::Text("Per-image RMS residual (px), max %.3f", max_rms);
    ImGui::PlotHistogram("##rms", rms.data(), static_cast<int>(rms.size()), 0, nullptr, 0,
                         max_rms * 1.1f, ImVec2(ImGui::GetContentRegionAvail().x, 110));
    if (ImGui::IsItemHovered()) {
      const float x = (ImGui::GetIO().MousePos.x - ImGui::GetItemRectMin().x) /
                      std::max(1.0f, ImGui::GetItemRectSize().x);
      const int v =
          std::clamp(static_cast<int>(x * rms.size()), 0, static_cast<int>(rms.size()) - 1);
      ImGui::SetTooltip("%s: %.3f px, %d outliers", snap.run.views[v].name.c_str(), rms[v],
                        fit.views[v].outliers);
    }
  }

  void DrawModels(const CalibrationSnapshot& snap) {
    const calib::ModelTrial& chosen = snap.run.Chosen();
    const auto& k = chosen.fit.intrinsics;
    ImGui::Text("Chosen: %s", chosen.lensmodel.c_str());
    if (k.size() >= 4) ImGui::Text("fx %.2f  fy %.2f  cx %.2f  cy %.2f", k[0], k[1], k[2], k[3]);
    ImGui::Text("rms %.4f px over %zu images", chosen.fit.rms_px, snap.run.views.size());
    const ImGuiTableFlags flags =
        ImGuiTableFlags_RowBg | ImGuiTableFlags_Borders | ImGuiTableFlags_SizingFixedFit;
    if (!ImGui::BeginTable("models", 5, flags)) return;
    ImGui::PushTextWrapPos(-1.0f);  // columns fit their text: wrapping would shrink them
    for (const char* h : {"model", "rms px", "sigma px", "halves / limit px", "verdict"})
      ImGui::TableSetupColumn(h);
    ImGui::TableHeadersRow();
    for (int i = 0; i < static_cast<int>(snap.run.choice.trials.size()); ++i) {
      const calib::ModelTrial& t = snap.run.choice.trials[i];
      ImGui::TableNextRow();
      if (i == snap.run.choice.chosen)
        ImGui::TableSetBgColor(ImGuiTableBgTarget_RowBg0, IM_COL32(40, 110, 50, 255));
      ImGui::TableSetColumnIndex(0);
      ImGui::Text("%s%s", t.short_name.c_str(), i == snap.run.choice.chosen ? " *" : "");
      if (!t.status.ok()) {
        ImGui::TableSetColumnIndex(4);
        ImGui::TextUnformatted("failed");
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", t.status.message().c_str());
        continue;
      }
      ImGui::TableSetColumnIndex(1);
      ImGui::Text("%.4f", t.fit.rms_px);
      ImGui::TableSetColumnIndex(2);
      ImGui::Text("%.4f", t.fit.noise_sigma_px);
      ImGui::TableSetColumnIndex(3);
      if (t.cross_validation_px < 0)
        ImGui::TextDisabled(t.halves_skipped ? "not needed" : "-");
      else
        ImGui::Text("%.4f / %.4f", t.cross_validation_px, calib::AgreementLimit_px(t));
      ImGui::TableSetColumnIndex(4);
      ImGui::TextUnformatted(calib::VerdictText(t).c_str());
    }
    ImGui::PopTextWrapPos();
    ImGui::EndTable();
  }

  void UpdateReport(const CalibrationSnapshot& snap) {
    static const char* kLevels[] = {"red", "yellow", "green"};
    report_ = {{"status", snap.status},
               {"images", std::to_string(snap.images.size())},
               {"views", std::to_string(snap.run.views.size())},
               {"rejected", std::to_string(snap.run.rejected.size())},
               {"excluded", std::to_string(snap.run.excluded.size())},
               {"camera_doubts", std::to_string(snap.run.camera_doubts.size())},
               {"readiness", kLevels[static_cast<int>(snap.readiness.level)]}};
    report_["folder"] = folder_;
    report_["attach"] = attach_path_;
    if (!attach_error_.empty()) report_["attach_error"] = attach_error_;
    if (snap.solved) {
      report_["model"] = snap.run.Chosen().short_name;
      report_["lensmodel"] = snap.run.Chosen().lensmodel;
      report_["rms_px"] = Format("%.6f", snap.run.Chosen().fit.rms_px);
      report_["fx"] = Format("%.6f", snap.run.Chosen().fit.intrinsics[0]);
      report_["models_tried"] = std::to_string(snap.run.choice.trials.size());
      report_["uncertainty_centre_px"] = Format("%.6f", snap.run.uncertainty.centre_px);
      report_["uncertainty_max_px"] = Format("%.6f", snap.run.uncertainty.max_px);
    }
  }

  std::string folder_;
  char board_[256] = "";
  char save_path_[1100] = "";
  int attach_stream_ = 0;     // version-2 projects: which stream's camera
  std::string attach_path_;   // the .cameramodel Attach checks and attaches
  std::string attach_saved_;  // the snapshot's saved_path attach_path_ last took
  std::string attach_error_;  // why the last Attach was refused ("" when it was not)
  CameraAttachCheck check_;   // the last check that passed (the confirmation shows it)
  int model_ = 0;             // 0 = auto, else LensModelShortNames()[model_ - 1]
  int selected_ = -1;
  int drawn_image_ = -1;
  uint64_t drawn_version_ = 0;
  cv::Mat detections_;
  std::map<std::string, std::string> report_;
};

}  // namespace

std::unique_ptr<Panel> MakeCalibrationPanel() { return std::make_unique<CalibrationPanel>(); }

}  // namespace fresco
