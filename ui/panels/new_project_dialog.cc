// New project (File > New project..., the Project panel's New): a form with what a project
// needs (scene, video, camera, poses, where to save it). Create builds the Project with its
// paths relative to the project file, checks it as `fresco run` does when it loads one (the
// JSON loader, then every file the project names: the same one-line "FILE: field: ..."
// messages), writes nothing when a check fails, and otherwise saves it atomically and opens
// it as Open does (the unsaved-changes prompt first; the recent list too). A scene, video,
// camera or poses file dropped on the window fills its field while the form is open.
#include "ui/core/panel.h"

#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/core/atomic_file.h"
#include "ui/core/project_paths.h"
#include "ui/panels/panels.h"
#include "ui/panels/path_field.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

class NewProjectDialog : public Panel {
 public:
  NewProjectDialog() { open = false; }
  const char* Title() const override { return kNewProjectTitle; }
  std::map<std::string, std::string> Report() const override {
    return {{"error", error_},        {"scene", form_.scene}, {"video", form_.video},
            {"camera", form_.camera}, {"poses", form_.poses}, {"project file", form_.project_file}};
  }

  bool AcceptDrop(const DroppedFile& file) override {
    std::string* field = FieldFor(file.kind, &form_);
    if (field) *field = file.path;
    return field != nullptr;
  }

  void Draw(UiContext& ui) override {
    if (!BeginPanel(*this)) {
      ImGui::End();
      return;
    }
    ProjectPathFields(&form_);
    if (ui.calibration) {
      const std::string calibrated = ui.calibration->Snapshot()->saved_path;
      if (!calibrated.empty() &&
          ImGui::SmallButton(("Use the camera just calibrated: " + calibrated).c_str()))
        form_.camera = calibrated;
    }
    PathField("Save to", "##project", "project.json to create", &form_.project_file, {".json"});
    if (ImGui::Button("Create")) Create(ui);
    ImGui::SameLine();
    if (ImGui::Button("Cancel")) {
      open = false;
      error_.clear();
    }
    if (!error_.empty()) {
      ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.4f, 0.4f, 1.0f));
      ImGui::TextWrapped("error: %s", error_.c_str());
      ImGui::PopStyleColor();
    }
    ImGui::End();
  }

 private:
  void Create(UiContext& ui) {
    Project project;
    if (Status s = BuildNewProject(form_, &project); !s.ok()) {
      error_ = s.message();
      return;
    }
    error_.clear();
    open = false;
    form_ = NewProjectForm();
    RequestOpen(ui, project.file_path);
  }

  NewProjectForm form_;
  std::string error_;
};

}  // namespace

Status BuildNewProject(const NewProjectForm& form, Project* project) {
  if (form.project_file.empty()) return Status::Error("project file: no path to save to");
  std::error_code ec;
  const fs::path file = fs::absolute(form.project_file, ec).lexically_normal();
  if (fs::exists(file, ec))
    return Status::Error(file.string() + ": exists already (open it with Open)");
  Project built;
  built.scene = PathRelativeTo(form.scene, file.string());
  built.camera = PathRelativeTo(form.camera, file.string());
  built.video = PathRelativeTo(form.video, file.string());
  built.poses = PathRelativeTo(form.poses, file.string());
  Project parsed;
  FRESCO_RETURN_IF_ERROR(CheckAsRunLoads(ProjectToJsonText(built), file.string(), &parsed));
  FRESCO_RETURN_IF_ERROR(MakeDirectories(file.parent_path().string()));
  FRESCO_RETURN_IF_ERROR(SaveProject(parsed, file.string()));
  *project = std::move(parsed);
  return Status::Ok();
}

std::unique_ptr<Panel> MakeNewProjectDialog() { return std::make_unique<NewProjectDialog>(); }

}  // namespace fresco
