#include "ui/core/project_paths.h"

#include <algorithm>
#include <filesystem>
#include <utility>

#include <nlohmann/json.hpp>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/capture.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

bool IsBuiltin(const std::string& path) { return path.rfind("builtin:", 0) == 0; }

std::string Editable(const Project& project, const std::string& written) {
  return IsBuiltin(written) ? written : project.Resolve(written);
}

}  // namespace

std::string PathRelativeTo(const std::string& typed, const std::string& project_file) {
  if (typed.empty() || IsUrlOrDevice(typed) || IsBuiltin(typed)) return typed;
  std::error_code ec;
  const fs::path absolute = fs::absolute(typed, ec).lexically_normal();
  if (ec) return typed;
  std::string relative = absolute.lexically_relative(fs::path(project_file).parent_path()).string();
  if (relative.empty()) return absolute.string();
  if (typed.back() == '/' && relative.back() != '/') relative += '/';
  return relative;
}

ProjectPaths EditablePaths(const Project& project) {
  const std::vector<StreamSpec> streams = project.Streams();
  ProjectPaths paths;
  paths.scene = Editable(project, project.scene);
  if (streams.empty()) return paths;
  paths.video = Editable(project, streams[0].video);
  paths.camera = Editable(project, streams[0].camera);
  paths.poses = Editable(project, streams[0].poses);
  return paths;
}

Status CheckAsRunLoads(const std::string& text, const std::string& file, Project* parsed,
                       bool require_poses) {
  FRESCO_RETURN_IF_ERROR(ParseProject(text, file, {}, parsed));
  FRESCO_RETURN_IF_ERROR(CheckOneStream(*parsed, "the app"));
  CaptureLoadOptions options;
  options.open_video = !IsUrlOrDevice(parsed->Streams()[0].video);
  options.require_poses = require_poses;
  Capture capture;
  return LoadCapture(*parsed, options, &capture);
}

Status CheckNewProject(const ProjectPaths& typed, const std::string& project_file,
                       bool require_poses, Project* parsed) {
  if (project_file.empty()) return Status::Error("project file: no path to save to");
  std::error_code ec;
  const fs::path file = fs::absolute(project_file, ec).lexically_normal();
  if (fs::exists(file, ec))
    return Status::Error(file.string() + ": exists already (open it with Open)");
  Project built;
  built.scene = PathRelativeTo(typed.scene, file.string());
  built.camera = PathRelativeTo(typed.camera, file.string());
  built.video = PathRelativeTo(typed.video, file.string());
  built.poses = PathRelativeTo(typed.poses, file.string());
  return CheckAsRunLoads(ProjectToJsonText(built), file.string(), parsed, require_poses);
}

Status RepairProjectPaths(const std::string& file, const ProjectPaths& typed, Project* repaired) {
  std::string text;
  FRESCO_RETURN_IF_ERROR(ReadFileToString(file, &text));
  nlohmann::ordered_json root;
  try {
    root = nlohmann::ordered_json::parse(text);
  } catch (const std::exception& e) {
    return Status::Error(file + ": not valid JSON: " + e.what());
  }
  if (!root.is_object()) return Status::Error(file + ": not a JSON object");
  // A version-2 file keeps its video, camera and poses in its one stream.
  nlohmann::ordered_json* stream = &root;
  if (root.contains("streams")) {
    if (!root["streams"].is_array() || root["streams"].size() != 1 ||
        !root["streams"][0].is_object())
      return Status::Error(file + ": streams: the app repairs a project with one video stream");
    stream = &root["streams"][0];
  }
  root["scene"] = PathRelativeTo(typed.scene, file);
  (*stream)["video"] = PathRelativeTo(typed.video, file);
  (*stream)["camera"] = PathRelativeTo(typed.camera, file);
  (*stream)["poses"] = PathRelativeTo(typed.poses, file);
  const std::string repaired_text = root.dump(2) + "\n";
  Project parsed;
  FRESCO_RETURN_IF_ERROR(CheckAsRunLoads(repaired_text, file, &parsed));
  FRESCO_RETURN_IF_ERROR(WriteFileAtomic(file, repaired_text));
  *repaired = std::move(parsed);
  return Status::Ok();
}

std::string* FieldFor(DroppedKind kind, ProjectPaths* paths) {
  switch (kind) {
    case DroppedKind::kScene:
      return &paths->scene;
    case DroppedKind::kVideo:
      return &paths->video;
    case DroppedKind::kCamera:
      return &paths->camera;
    case DroppedKind::kPoses:
      return &paths->poses;
    case DroppedKind::kProject:
    case DroppedKind::kUnknown:
      break;
  }
  return nullptr;
}

std::vector<std::string> BrowseEntries(const std::string& typed,
                                       const std::vector<std::string>& extensions) {
  const std::string::size_type slash = typed.rfind('/');
  const std::string folder = slash == std::string::npos ? "." : typed.substr(0, slash + 1);
  std::string prefix = slash == std::string::npos ? typed : typed.substr(slash + 1);
  std::vector<std::string> entries;
  std::error_code ec;
  // A field holding a file's whole name (picked before) lists its whole folder, to pick
  // another: the name filters the list only while it is being typed.
  if (!prefix.empty() && fs::is_regular_file(typed, ec)) prefix.clear();
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

std::string ParentFolder(const std::string& typed) {
  const std::string::size_type slash = typed.rfind('/');
  fs::path folder =
      slash == std::string::npos ? fs::path(".") : fs::path(typed.substr(0, slash + 1));
  folder = folder.lexically_normal();
  if (folder.filename().empty()) folder = folder.parent_path();  // "a/b/" -> "a/b"
  if (folder.empty()) folder = ".";
  if (folder.is_absolute() && folder == folder.root_path()) return "";
  fs::path parent;
  if (folder == "." || folder.filename() == "..") {
    parent = folder == "." ? fs::path("..") : folder / "..";
  } else {
    parent = folder.parent_path();
    if (parent.empty()) parent = ".";
  }
  std::string text = parent.string();
  if (text.back() != '/') text += '/';
  return text;
}

}  // namespace fresco
