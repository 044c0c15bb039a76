#include "ui/panels/path_field.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <set>

#include <imgui.h>
#include <imgui_internal.h>
#include <imgui_stdlib.h>

#include "ui/core/panel.h"
#include "ui/core/project_paths.h"

namespace fresco {

namespace fs = std::filesystem;

namespace {

// The folder a typed path lists ("." for a bare name).
std::string ListedFolder(const std::string& value) {
  const std::string::size_type slash = value.rfind('/');
  return slash == std::string::npos ? "." : value.substr(0, slash + 1);
}

// Remembers the folder `value` lists, when it exists, as the last folder used.
void Remember(const std::string& value, std::string* last_folder) {
  if (!last_folder || value.empty()) return;
  std::error_code ec;
  const fs::path folder = fs::absolute(ListedFolder(value), ec).lexically_normal();
  if (ec || !fs::is_directory(folder, ec)) return;
  std::string text = folder.string();
  if (text.back() != '/') text += '/';
  *last_folder = text;
}

// The ImGui ids of the "..." lists opened so far.
std::set<ImGuiID>& BrowseLists() {
  static std::set<ImGuiID> ids;
  return ids;
}

}  // namespace

void LetAClickOutsideABrowseListThrough() {
  ImGuiContext& g = *GImGui;
  if (g.OpenPopupStack.empty() || !ImGui::IsMouseClicked(0)) return;
  const ImGuiPopupData& top = g.OpenPopupStack.back();
  if (!BrowseLists().count(top.PopupId)) return;
  ImGuiWindow* hovered = g.HoveredWindow;
  if (hovered && top.Window && hovered->RootWindow == top.Window->RootWindow) return;  // in it
  ImGui::ClosePopupToLevel(g.OpenPopupStack.Size - 1, false);
  if (hovered) ImGui::FocusWindow(hovered);
}

int CountImages(const std::string& folder) {
  static const char* kImages[] = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff"};
  std::error_code ec;
  int count = 0;
  for (fs::directory_iterator it(folder.empty() ? "." : folder, ec), end; !ec && it != end;
       it.increment(ec)) {
    if (!it->is_regular_file(ec)) continue;
    std::string ext = it->path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    count += std::find(std::begin(kImages), std::end(kImages), ext) != std::end(kImages);
  }
  return count;
}

std::string BrowseNote(const std::string& value, const PathFieldOptions& options, size_t entries) {
  const int images = options.folder_of_images ? CountImages(ListedFolder(value)) : 0;
  if (images > 0)
    return "this folder: " + std::to_string(images) + (images == 1 ? " image" : " images") +
           (!value.empty() && value.back() == '/' ? " (chosen)" : "");
  return entries == 0 ? "nothing here fits" : "";
}

bool PathField(const char* label, const char* id, const char* hint, std::string* value,
               const PathFieldOptions& options) {
  LetAClickOutsideABrowseListThrough();
  ImGui::TextUnformatted(label);
  SameLineInFieldColumn();
  FitNextItem("...", options.min_width_px);
  bool changed = ImGui::InputTextWithHint(id, hint, value);
  if (ImGui::IsItemDeactivatedAfterEdit()) Remember(*value, options.last_folder);
  ImGui::SameLine();
  ImGui::PushID(id);
  if (ImGui::Button("...")) {
    ImGui::OpenPopup("browse");
    BrowseLists().insert(ImGui::GetID("browse"));
    // The list starts in the folder the field names (a folder typed without its '/' lists
    // what is in it); an empty field's in the last folder used, not the launch folder.
    std::error_code ec;
    if (value->empty() && options.last_folder && !options.last_folder->empty()) {
      *value = *options.last_folder;
      changed = true;
    } else if (!value->empty() && value->back() != '/' && fs::is_directory(*value, ec)) {
      *value += '/';
      changed = true;
    }
  }
  if (ImGui::BeginPopup("browse")) {
    // A folder opens in place (the list stays open); a file is picked and closes the list.
    const std::string folder = ListedFolder(*value);
    std::error_code ec;
    ImGui::TextDisabled("%s", fs::absolute(folder, ec).lexically_normal().string().c_str());
    const std::string parent = ParentFolder(*value);
    if (!parent.empty() &&
        ImGui::Selectable("../ (the folder above)", false, ImGuiSelectableFlags_DontClosePopups)) {
      *value = parent;
      changed = true;
    }
    const std::vector<std::string> entries = BrowseEntries(*value, options.extensions);
    const std::string note = BrowseNote(*value, options, entries.size());
    if (note.rfind("this folder", 0) == 0)
      ImGui::TextColored(ImVec4(0.5f, 0.9f, 0.5f, 1), "%s", note.c_str());
    else if (!note.empty())
      ImGui::TextDisabled("%s", note.c_str());
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
    if (changed) Remember(*value, options.last_folder);
  }
  ImGui::PopID();
  return changed;
}

bool ProjectPathFields(ProjectPaths* paths, std::string* last_folder) {
  const bool changed = SceneVideoCameraFields(paths, last_folder);
  return PosesField(&paths->poses, last_folder) || changed;
}

bool SceneVideoCameraFields(ProjectPaths* paths, std::string* last_folder) {
  bool changed =
      PathField("Scene", "##scene", "mesh: scene.gltf, .glb, .ply or .obj", &paths->scene,
                {.extensions = {".gltf", ".glb", ".ply", ".obj"}, .last_folder = last_folder});
  changed |= PathField("Video", "##video", "video file, frame folder/ or live URL (udp://...)",
                       &paths->video,
                       {.extensions = {".mp4", ".mkv", ".avi", ".mov", ".webm"},
                        .folder_of_images = true,
                        .last_folder = last_folder});
  changed |= PathField("Camera", "##camera", ".cameramodel or COLMAP cameras.txt", &paths->camera,
                       {.extensions = {".cameramodel", ".txt"}, .last_folder = last_folder});
  return changed;
}

bool PosesField(std::string* poses, std::string* last_folder, const char* hint) {
  return PathField("Poses", "##poses", hint, poses,
                   {.extensions = {".txt", ".tum"}, .last_folder = last_folder});
}

}  // namespace fresco
