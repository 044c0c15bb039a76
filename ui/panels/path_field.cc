#include "ui/panels/path_field.h"

#include <imgui.h>
#include <imgui_stdlib.h>

#include "ui/core/panel.h"
#include "ui/core/project_paths.h"

namespace fresco {

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
    const std::vector<std::string> entries = BrowseEntries(*value, extensions);
    if (entries.empty()) ImGui::TextDisabled("nothing here fits");
    for (const std::string& entry : entries) {
      if (!ImGui::Selectable(entry.c_str())) continue;
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
