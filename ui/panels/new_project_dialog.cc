// New project (File > New project..., the Project panel's New): a form with what a project
// needs (scene, video, camera, poses, where to save it). Create builds the Project with its
// paths relative to the project file, checks it as `fresco run` does when it loads one (the
// JSON loader, then every file the project names: the same one-line "FILE: field: ..."
// messages), writes nothing when a check fails, and otherwise saves it atomically and opens
// it as Open does (the unsaved-changes prompt first; the recent list too).
#include "ui/core/panel.h"  // imgui.h first: imgui_stdlib.h needs it

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <imgui_stdlib.h>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/capture.h"
#include "ui/panels/panels.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

// A typed path (absolute, or relative to the working folder) as the project file at
// `project_file` writes it: relative to its folder. URLs, "device:N" and "" stay as typed;
// a folder's trailing '/' stays.
std::string RelativeTo(const std::string& typed, const fs::path& project_file) {
  if (typed.empty() || IsUrlOrDevice(typed)) return typed;
  std::error_code ec;
  const fs::path absolute = fs::absolute(typed, ec).lexically_normal();
  if (ec) return typed;
  std::string relative = absolute.lexically_relative(project_file.parent_path()).string();
  if (relative.empty()) return absolute.string();
  if (typed.back() == '/' && relative.back() != '/') relative += '/';
  return relative;
}

// The entries of the folder a typed path is in (or of the typed folder), whose names start
// with what is typed after the last '/' and end with one of `extensions` (folders always).
std::vector<std::string> BrowseEntries(const std::string& typed,
                                       const std::vector<std::string>& extensions) {
  const std::string::size_type slash = typed.rfind('/');
  const std::string folder = slash == std::string::npos ? "." : typed.substr(0, slash + 1);
  const std::string prefix = slash == std::string::npos ? typed : typed.substr(slash + 1);
  std::vector<std::string> entries;
  std::error_code ec;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(prefix, 0) != 0 || name.front() == '.') continue;
    const bool is_folder = it->is_directory(ec);
    bool fits = is_folder;
    for (const std::string& ext : extensions)
      fits = fits || (name.size() >= ext.size() &&
                      name.compare(name.size() - ext.size(), ext.size(), ext) == 0);
    if (!fits) continue;
    entries.push_back((slash == std::string::npos ? "" : folder) + name + (is_folder ? "/" : ""));
  }
  std::sort(entries.begin(), entries.end());
  return entries;
}

class NewProjectDialog : public Panel {
 public:
  NewProjectDialog() { open = false; }
  const char* Title() const override { return kNewProjectTitle; }
  std::map<std::string, std::string> Report() const override {
    return {{"error", error_},       {"scene", form_.scene}, {"video", form_.video},
            {"camera", form_.camera}, {"poses", form_.poses}, {"project file", form_.project_file}};
  }

  void Draw(UiContext& ui) override {
    if (!BeginPanel(*this)) {
      ImGui::End();
      return;
    }
    PathField("Scene", "##scene", "mesh: scene.gltf, .glb, .ply or .obj", &form_.scene,
              {".gltf", ".glb", ".ply", ".obj"});
    PathField("Video", "##video", "video file, frame folder/ or live URL (udp://...)",
              &form_.video, {".mp4", ".mkv", ".avi", ".mov", ".webm"});
    PathField("Camera", "##camera", ".cameramodel or COLMAP cameras.txt", &form_.camera,
              {".cameramodel", ".txt"});
    if (ui.calibration) {
      const std::string calibrated = ui.calibration->Snapshot()->saved_path;
      if (!calibrated.empty() &&
          ImGui::SmallButton(("Use the camera just calibrated: " + calibrated).c_str()))
        form_.camera = calibrated;
    }
    PathField("Poses", "##poses", "COLMAP images.txt, TUM file, or tcp:// live feed", &form_.poses,
              {".txt", ".tum"});
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
  // A labelled path input, and a "..." button listing the folder's entries that fit.
  void PathField(const char* label, const char* id, const char* hint, std::string* value,
                 const std::vector<std::string>& extensions) {
    ImGui::TextUnformatted(label);
    ImGui::SameLine(80);
    FitNextItem("...");
    ImGui::InputTextWithHint(id, hint, value);
    ImGui::SameLine();
    ImGui::PushID(id);
    if (ImGui::Button("...")) ImGui::OpenPopup("browse");
    if (ImGui::BeginPopup("browse")) {
      const std::vector<std::string> entries = BrowseEntries(*value, extensions);
      if (entries.empty()) ImGui::TextDisabled("nothing here fits");
      for (const std::string& entry : entries)
        if (ImGui::Selectable(entry.c_str())) *value = entry;
      ImGui::EndPopup();
    }
    ImGui::PopID();
  }

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
  built.scene = RelativeTo(form.scene, file);
  built.camera = RelativeTo(form.camera, file);
  built.video = RelativeTo(form.video, file);
  built.poses = RelativeTo(form.poses, file);
  // The checks `fresco run` makes on loading: the JSON loader on the text to be written,
  // then every file the project names (as LoadCapture reads them; a live video is not
  // opened here).
  Project parsed;
  FRESCO_RETURN_IF_ERROR(ParseProject(ProjectToJsonText(built), file.string(), {}, &parsed));
  CaptureLoadOptions options;
  options.open_video = !IsUrlOrDevice(parsed.video);
  Capture capture;
  FRESCO_RETURN_IF_ERROR(LoadCapture(parsed, options, &capture));
  FRESCO_RETURN_IF_ERROR(MakeDirectories(file.parent_path().string()));
  FRESCO_RETURN_IF_ERROR(SaveProject(parsed, file.string()));
  *project = std::move(parsed);
  return Status::Ok();
}

std::unique_ptr<Panel> MakeNewProjectDialog() { return std::make_unique<NewProjectDialog>(); }

}  // namespace fresco
