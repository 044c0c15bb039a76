#include "ui/panels/path_field.h"

#include <filesystem>

#include <imgui.h>
#include <imgui_stdlib.h>

#include "ui/core/panel.h"
#include "ui/core/project_paths.h"

namespace fresco {

namespace fs = std::filesystem;

bool PathField(const char* label, const char* id, const char* hint, std::string* value,
               const std::vector<std::string>& extensions) {
  ImGui::TextUnformatted(label);
  ImGui::SameLine(80);
  FitNextItem("...");
  bool changed = ImGui::InputTextWithHint(id, hint, value);
  ImGui::SameLine();
  ImGui::PushID(id);
  if (ImGui::Button("...")) ImGui::OpenPopup("browse");
  if (ImGui::BeginPopup("browse")) {
    // A folder opens in place (the list stays open); a file is picked and closes the list.
    const std::string::size_type slash = value->rfind('/');
    const std::string folder = slash == std::string::npos ? "." : value->substr(0, slash + 1);
    std::error_code ec;
    ImGui::TextDisabled("%s", fs::absolute(folder, ec).lexically_normal().string().c_str());
    const std::string parent = ParentFolder(*value);
    if (!parent.empty() &&
        ImGui::Selectable("../ (the folder above)", false, ImGuiSelectableFlags_DontClosePopups)) {
      *value = parent;
      changed = true;
    }
    const std::vector<std::string> entries = BrowseEntries(*value, extensions);
    if (entries.empty()) ImGui::TextDisabled("nothing here fits");
    for (const std::string& entry : entries) {
      const bool is_folder = entry.back() == '/';
      const std::string shown = entry.substr(entry.rfind('/', entry.size() - 2) + 1);
      if (!ImGui::Selectable(shown.c_str(), false,
                             is_folder ? ImGuiSelectableFlags_DontClosePopups : 0))
        continue;
      *value = entry;
      changed = true;
    }
    ImGui::EndPopup();
  }
  ImGui::PopID();
  return changed;
}

bool ProjectPathFields(ProjectPaths* paths) {
  const bool changed = SceneVideoCameraFields(paths);
  return PosesField(&paths->poses) || changed;
}

bool SceneVideoCameraFields(ProjectPaths* paths) {
  bool changed = PathField("Scene", "##scene", "mesh: scene.gltf, .glb, .ply or .obj",
                           &paths->scene, {".gltf", ".glb", ".ply", ".obj"});
  changed |= PathField("Video", "##video", "video file, frame folder/ or live URL (udp://...)",
                       &paths->video, {".mp4", ".mkv", ".avi", ".mov", ".webm"});
  changed |= PathField("Camera", "##camera", ".cameramodel or COLMAP cameras.txt", &paths->camera,
                       {".cameramodel", ".txt"});
  return changed;
}

bool PosesField(std::string* poses, const char* hint) {
  return PathField("Poses", "##poses", hint, poses, {".txt", ".tum"});
}

}  // namespace fresco
