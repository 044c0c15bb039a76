// New project (File > New project..., the Project panel's New): a form with what a project
// needs (scene, video, camera, poses, where to save it). Create builds the Project with its
// paths relative to the project file, checks it as `fresco run` does when it loads one (the
// JSON loader, then every file the project names: the same one-line "FILE: field: ..."
// messages), writes nothing when a check fails, and otherwise saves it atomically and opens
// it as Open does (the unsaved-changes prompt first; the recent list too). A scene, video,
// camera or poses file dropped on the window fills its field while the form is open.
// Poses may instead be bootstrapped with COLMAP (new_project_bootstrap.h): Create then runs
// COLMAP in the background (its own PosesRunner: steps, elapsed time, Cancel; the app stays
// responsive) and, when the poses are placed on the mesh, writes them beside the project,
// saves and opens it; a failure is one error in the form, and nothing is written.
#include "ui/core/panel.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <imgui_stdlib.h>

#include "pipeline/core/atomic_file.h"
#include "ui/core/new_project_bootstrap.h"
#include "ui/core/project_paths.h"
#include "ui/panels/panels.h"
#include "ui/panels/path_field.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

class NewProjectDialog : public Panel {
 public:
  NewProjectDialog() { open = false; }
  ~NewProjectDialog() override {
    if (!runner_) return;
    runner_.reset();  // stops COLMAP
    DiscardNewProjectBootstrap(bootstrap_);
  }
  const char* Title() const override { return kNewProjectTitle; }
  std::map<std::string, std::string> Report() const override {
    return {{"error", error_},
            {"scene", form_.scene},
            {"video", form_.video},
            {"camera", form_.camera},
            {"poses", form_.poses},
            {"project file", form_.project_file},
            {"poses from", form_.bootstrap ? "bootstrap with COLMAP" : "file"},
            {"control points", form_.colmap.control_points},
            {"running", runner_ ? "yes" : "no"},
            {"status", runner_ ? runner_->Snapshot()->status : std::string()},
            {"workspace", bootstrap_.workspace},
            {"bootstrapped", summary_}};
  }

  bool Busy() const override { return runner_ != nullptr; }

  bool AcceptDrop(const DroppedFile& file) override {
    if (runner_) return false;  // the form is fixed while COLMAP runs
    std::string* field = FieldFor(file.kind, &form_);
    if (field) *field = file.path;
    return field != nullptr;
  }

  void Draw(UiContext& ui) override {
    if (PollBootstrap(ui)) return;  // the bootstrapped project was just made, the form closed
    if (!open && runner_) {         // hidden (View menu) while COLMAP runs: as closing it, below
      runner_->Cancel();
      open = true;
    }
    if (!BeginPanel(*this)) {
      ImGui::End();
      return;
    }
    if (!open && runner_) {  // closed or hidden while COLMAP runs: stop it, show that it stopped
      runner_->Cancel();
      open = true;
    }
    ImGui::BeginDisabled(runner_ != nullptr);
    SceneVideoCameraFields(&form_, &ui.state->last_folder);
    if (ui.calibration) {
      const std::string calibrated = ui.calibration->Snapshot()->saved_path;
      if (!calibrated.empty() &&
          ImGui::SmallButton(("Use the camera just calibrated: " + calibrated).c_str()))
        form_.camera = calibrated;
    }
    DrawPosesChoice(&ui.state->last_folder);
    PathField("Save to", "##project", "project.json to create", &form_.project_file,
              {.extensions = {".json"}, .last_folder = &ui.state->last_folder});
    if (ImGui::Button("Create")) Create(ui);
    ImGui::EndDisabled();
    ImGui::SameLine();
    if (ImGui::Button("Cancel")) {
      if (runner_) {
        runner_->Cancel();  // the form stays, and says it was cancelled
      } else {
        open = false;
        error_.clear();
      }
    }
    if (runner_) {
      const auto snap = runner_->Snapshot();
      ColmapProgressBar(*snap);
      ImGui::TextWrapped("%s", snap->status.c_str());
    }
    if (!error_.empty()) {
      ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.4f, 0.4f, 1.0f));
      ImGui::TextWrapped("error: %s", error_.c_str());
      ImGui::PopStyleColor();
    }
    ImGui::End();
  }

 private:
  // Poses from a file (or live feed), or bootstrapped with COLMAP: then the control points
  // (or rough poses) that place them on the mesh and COLMAP's speed options.
  void DrawPosesChoice(std::string* last_folder) {
    ImGui::TextUnformatted("Poses from");
    SameLineInFieldColumn();
    int choice = form_.bootstrap ? 1 : 0;
    ImGui::RadioButton("a file or live feed", &choice, 0);
    ImGui::SameLine();
    ImGui::RadioButton("bootstrap with COLMAP", &choice, 1);
    form_.bootstrap = choice == 1;
    if (!form_.bootstrap) {
      PosesField(&form_.poses, last_folder);
      return;
    }
    NewProjectBootstrapOptions& o = form_.colmap;
    PathField("Control", "##control",
              "control points: >= 3 known points on the mesh, NAME X Y Z IMAGE U V ...",
              &o.control_points, {.extensions = {".txt"}, .last_folder = last_folder});
    PosesField(&form_.poses, last_folder,
               "optional: rough poses that place COLMAP's (without control points)");
    ImGui::Indent(80);
    ImGui::Checkbox("fit to the mesh (ICP)", &o.refine_mesh);
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip(
          "then fit COLMAP's sparse points to the mesh's surface: corrects\n"
          "control points measured only roughly");
    ImGui::SetNextItemWidth(120);
    ImGui::InputInt("max features", &o.max_features, 500);
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip(
          "SIFT features per image; 0 = COLMAP's default (8192).\n"
          "1000-2000 is much faster on small images");
    ImGui::SameLine();
    ImGui::SetNextItemWidth(120);
    ImGui::InputInt("max image size", &o.max_image_size, 100);
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("longest side for feature extraction; 0 = COLMAP's default (3200)");
    o.max_features = std::max(0, o.max_features);
    o.max_image_size = std::max(0, o.max_image_size);
    FitNextItem("COLMAP program");
    ImGui::InputTextWithHint("COLMAP program", "colmap on PATH", &o.colmap_program);
    ImGui::Unindent(80);
  }

  void Create(UiContext& ui) {
    error_.clear();
    summary_.clear();
    if (form_.bootstrap) {
      StartBootstrap();
      return;
    }
    Project project;
    if (Status s = BuildNewProject(form_, &project); !s.ok()) {
      error_ = s.message();
      return;
    }
    Opened(ui, project.file_path);
  }

  void StartBootstrap() {
    if (Status s = PrepareNewProjectBootstrap(form_, form_.project_file, form_.colmap, &bootstrap_);
        !s.ok()) {
      error_ = s.message();
      return;
    }
    runner_ = std::make_unique<PosesRunner>();
    runner_->Run(bootstrap_.request);
  }

  // A bootstrap that finished: the project written and opened (true), or the error.
  bool PollBootstrap(UiContext& ui) {
    if (!runner_) return false;
    const auto snap = runner_->Snapshot();
    if (!snap->has_request || snap->busy) return false;
    Project project;
    const Status s = FinishNewProjectBootstrap(bootstrap_, *snap, &project, &summary_);
    runner_.reset();
    if (!s.ok()) {
      error_ = s.message();
      return false;
    }
    Opened(ui, project.file_path);
    ui.state->pending_open_note = "poses: " + summary_;
    return true;
  }

  void Opened(UiContext& ui, const std::string& file) {
    open = false;
    form_ = NewProjectForm();
    RequestOpen(ui, file);
  }

  NewProjectForm form_;
  std::string error_;
  // A bootstrap under way (runner_ set) or the last one.
  NewProjectBootstrap bootstrap_;
  std::unique_ptr<PosesRunner> runner_;
  std::string summary_;  // how the last bootstrapped project's poses were made
};

}  // namespace

Status BuildNewProject(const NewProjectForm& form, Project* project) {
  Project parsed;
  FRESCO_RETURN_IF_ERROR(CheckNewProject(form, form.project_file, true, &parsed));
  const fs::path file = parsed.file_path;
  FRESCO_RETURN_IF_ERROR(MakeDirectories(file.parent_path().string()));
  FRESCO_RETURN_IF_ERROR(SaveProject(parsed, file.string()));
  *project = std::move(parsed);
  return Status::Ok();
}

std::unique_ptr<Panel> MakeNewProjectDialog() { return std::make_unique<NewProjectDialog>(); }

}  // namespace fresco
