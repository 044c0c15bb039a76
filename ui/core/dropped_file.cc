#include "ui/core/dropped_file.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "ui/core/panel.h"
#include "ui/panels/panels.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

constexpr size_t kMaxJsonBytes = 16 << 20;  // a project is small; a larger .json is not one

std::string LowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

bool IsNumber(const std::string& token) {
  char* end = nullptr;
  std::strtod(token.c_str(), &end);
  return end && *end == '\0' && !token.empty();
}

// A COLMAP cameras.txt or images.txt (by its header comment, else by its first line), or a
// TUM trajectory (8 numbers a line).
DroppedKind ClassifyText(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  for (int n = 0; n < 64 && std::getline(in, line); ++n) {
    if (line.rfind("# Camera list", 0) == 0) return DroppedKind::kCamera;
    if (line.rfind("# Image list", 0) == 0) return DroppedKind::kPoses;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    std::vector<std::string> tokens;
    for (std::string t; words >> t;) tokens.push_back(t);
    const bool all_numbers = std::all_of(tokens.begin(), tokens.end(), IsNumber);
    if (tokens.size() == 8 && all_numbers) return DroppedKind::kPoses;  // TUM
    if (tokens.size() >= 5 && IsNumber(tokens[0]) && !IsNumber(tokens[1]))
      return DroppedKind::kCamera;  // CAMERA_ID MODEL WIDTH HEIGHT PARAMS...
    if (tokens.size() >= 10 && IsNumber(tokens[0]) && IsNumber(tokens[8]))
      return DroppedKind::kPoses;  // IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME
    break;
  }
  const std::string name = fs::path(path).filename().string();
  if (name == "cameras.txt") return DroppedKind::kCamera;
  if (name == "images.txt") return DroppedKind::kPoses;
  return DroppedKind::kUnknown;
}

bool IsProjectJson(const std::string& path) {
  std::error_code ec;
  if (fs::file_size(path, ec) > kMaxJsonBytes || ec) return false;
  std::ifstream in(path);
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  return j.is_object() && j.contains("fresco");
}

}  // namespace

DroppedFile ClassifyDroppedPath(const std::string& path) {
  DroppedFile file;
  file.path = path;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) {
    file.why = path + ": dropped, but it does not exist";
    return file;
  }
  if (fs::is_directory(status)) {  // a folder of frames
    file.kind = DroppedKind::kVideo;
    if (file.path.empty() || file.path.back() != '/') file.path += '/';
    return file;
  }
  const std::string ext = LowerExtension(path);
  for (const char* e : {".gltf", ".glb", ".ply", ".obj"})
    if (ext == e) file.kind = DroppedKind::kScene;
  for (const char* e : {".mp4", ".mkv", ".avi", ".mov", ".webm", ".m4v", ".mpg", ".mpeg", ".ts"})
    if (ext == e) file.kind = DroppedKind::kVideo;
  if (ext == ".cameramodel") file.kind = DroppedKind::kCamera;
  if (ext == ".tum") file.kind = DroppedKind::kPoses;
  if (ext == ".txt") file.kind = ClassifyText(path);
  if (ext == ".json" && IsProjectJson(path)) file.kind = DroppedKind::kProject;
  if (file.kind != DroppedKind::kUnknown) return file;
  file.why =
      path + (ext == ".json" ? ": dropped, but it is not a Fresco project (no \"fresco\" key)"
                             : ": dropped, but it is not a project, mesh (.gltf, .glb, "
                               ".ply, .obj), video, camera (.cameramodel, cameras.txt) "
                               "or poses (images.txt, TUM) file");
  return file;
}

const char* DroppedKindName(DroppedKind kind) {
  switch (kind) {
    case DroppedKind::kProject:
      return "project";
    case DroppedKind::kScene:
      return "scene";
    case DroppedKind::kVideo:
      return "video";
    case DroppedKind::kCamera:
      return "camera";
    case DroppedKind::kPoses:
      return "poses";
    case DroppedKind::kUnknown:
      break;
  }
  return "unknown";
}

void DropPaths(UiContext& ui, const std::vector<std::string>& paths) {
  ui.dropped_paths.insert(ui.dropped_paths.end(), paths.begin(), paths.end());
}

void PlaceDroppedPaths(UiContext& ui, std::vector<std::unique_ptr<Panel>>& panels) {
  auto find = [&](const std::string& title) -> Panel* {
    for (auto& panel : panels)
      if (title == panel->Title()) return panel.get();
    return nullptr;
  };
  for (const std::string& path : ui.dropped_paths) {
    const DroppedFile file = ClassifyDroppedPath(path);
    if (file.kind == DroppedKind::kUnknown) {
      ui.state->message = "error: " + file.why;
      continue;
    }
    if (file.kind == DroppedKind::kProject) {
      RequestOpen(ui, file.path);
      continue;
    }
    // A field: the New project form when it is open, else the path editor of the project
    // (open, or waiting for repair), else a new form.
    Panel* form = find(kNewProjectTitle);
    Panel* project = find(kProjectPanelTitle);
    const bool to_project =
        !(form && form->open) && project && (ui.state->has_project || ui.state->has_unopened);
    Panel* target = to_project ? project : form;
    if (!target || !target->AcceptDrop(file)) {
      ui.state->message = "error: " + file.path + ": dropped, but nothing takes a " +
                          DroppedKindName(file.kind) + " file now";
      continue;
    }
    target->open = true;
    ui.state->message = std::string("dropped ") + DroppedKindName(file.kind) + " " + file.path +
                        " into " + target->Title() +
                        (to_project ? " (Apply and save keeps it)" : "");
  }
  ui.dropped_paths.clear();
}

}  // namespace fresco
