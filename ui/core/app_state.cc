#include "ui/core/app_state.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "pipeline/core/atomic_file.h"
#include "pipeline/paint/grouping.h"

namespace fresco {
namespace {

constexpr size_t kMaxRecent = 10;
constexpr size_t kMaxUndo = 100;

// Applies one edit with the pipeline's own ApplyGroupingEdits.
Status Apply(const std::vector<GroupSpec>& current, const GroupingEdit& edit, int num_triangles,
             std::vector<GroupSpec>* result) {
  Grouping grouping;
  grouping.groups = current;
  grouping.RebuildIndex(num_triangles);
  FRESCO_RETURN_IF_ERROR(ApplyGroupingEdits({edit}, num_triangles, &grouping));
  *result = grouping.groups;
  return Status::Ok();
}

// The files the project names must exist before the app calls it opened: a missing video
// is one clear error naming the project, the key and the path (live sources and built-in
// scenes are not files).
Status CheckInputsExist(const Project& project, const std::string& key_prefix = "") {
  const std::pair<const char*, const std::string*> inputs[] = {{"scene", &project.scene},
                                                               {"camera", &project.camera},
                                                               {"video", &project.video},
                                                               {"poses", &project.poses}};
  for (const auto& [key, value] : inputs) {
    if (value->empty() || IsUrlOrDevice(*value) || value->rfind("builtin:", 0) == 0) continue;
    const std::string path = project.Resolve(*value);
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))
      return Status::Error(project.file_path + ": " +
                           (std::string(key) == "scene" ? "" : key_prefix) + key + ": " + path +
                           " does not exist");
  }
  return Status::Ok();
}

}  // namespace

Status AppState::Open(const std::string& path) {
  Project loaded;
  has_unopened = false;
  FRESCO_RETURN_IF_ERROR(LoadProject(path, {}, &loaded));
  // One stream is edited as version-1 keys: a version-2 file's one stream is saved back as
  // version 1 (the same project). Several streams paint and are saved as they are; their
  // paths are edited in the file.
  const size_t streams = loaded.Streams().size();
  if (streams == 1) {
    loaded = loaded.ForStream(0);
    if (Status s = CheckInputsExist(loaded); !s.ok()) {
      unopened = loaded;  // its paths can be repaired in the Project panel
      has_unopened = true;
      return s;
    }
  }
  for (size_t i = 0; streams > 1 && i < streams; ++i)
    FRESCO_RETURN_IF_ERROR(CheckInputsExist(loaded.ForStream(static_cast<int>(i)),
                                            "streams[" + std::to_string(i) + "]."));
  project = loaded;
  saved = loaded;
  has_project = true;
  dirty = false;
  undo.clear();
  redo.clear();
  selected_groups.clear();
  selected_triangles.clear();
  RememberFolderOf(loaded.file_path);
  AddRecent(loaded.file_path);
  message = "opened " + loaded.file_path;
  return Status::Ok();
}

Status AppState::Save(const std::string& path) {
  if (!has_project) return Status::Error("no project to save");
  const std::string target = path.empty() ? project.file_path : path;
  FRESCO_RETURN_IF_ERROR(SaveProject(project, target));
  // Re-read what was written, so paths are as they resolve from the new place.
  Project written;
  FRESCO_RETURN_IF_ERROR(LoadProject(target, {}, &written));
  project = written;
  saved = written;
  dirty = false;
  RememberFolderOf(written.file_path);
  AddRecent(written.file_path);
  message = "saved " + written.file_path;
  return Status::Ok();
}

void AppState::BeginEdit() {
  undo.push_back(project);
  if (undo.size() > kMaxUndo) undo.erase(undo.begin());
  redo.clear();
  dirty = true;
}

Status AppState::RepairPaths(const ProjectPaths& typed, std::string* file) {
  if (!has_unopened && !has_project) return Status::Error("no project to repair");
  *file = has_unopened ? unopened.file_path : project.file_path;
  Project repaired;
  FRESCO_RETURN_IF_ERROR(RepairProjectPaths(*file, typed, &repaired));
  message = "saved the paths of " + *file;
  if (has_unopened) {
    has_unopened = false;
    return Status::Ok();
  }
  const Project paths = repaired.ForStream(0);
  const bool had_edits = dirty;  // the file now has these paths: no new unsaved edit
  BeginEdit();
  dirty = had_edits;
  for (Project* p : {&project, &saved}) {  // the file has these paths, its other keys as before
    p->scene = paths.scene;
    p->video = paths.video;
    p->camera = paths.camera;
    p->poses = paths.poses;
  }
  return Status::Ok();
}

bool AppState::Undo() {
  if (undo.empty()) return false;
  redo.push_back(project);
  project = undo.back();
  undo.pop_back();
  dirty = !(project == saved);
  message = "undone: " + DescribeProjectChange(redo.back(), project, "back to");
  return true;
}

bool AppState::Redo() {
  if (redo.empty()) return false;
  undo.push_back(project);
  project = redo.back();
  redo.pop_back();
  dirty = !(project == saved);
  message = "redone: " + DescribeProjectChange(undo.back(), project, "to");
  return true;
}

std::string DescribeProjectChange(const Project& before, const Project& after,
                                  const std::string& to) {
  std::string said;
  const auto say = [&](const std::string& what) { said += (said.empty() ? "" : "; ") + what; };
  if (before.scene != after.scene) say("scene " + to + " " + after.scene);
  const std::vector<StreamSpec> a = before.Streams(), b = after.Streams();
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    const int index = static_cast<int>(i);
    if (a[i].camera != b[i].camera)
      say(after.StreamKey(index, "camera") + " " + to + " " + b[i].camera);
    if (a[i].video != b[i].video)
      say(after.StreamKey(index, "video") + " " + to + " " + b[i].video);
    if (a[i].poses != b[i].poses)
      say(after.StreamKey(index, "poses") + " " + to + " " + b[i].poses);
  }
  if (a.size() != b.size()) say("the streams");
  if (!(before.grouping == after.grouping)) say("the grouping");
  if (!(before.pipeline == after.pipeline)) say("the pipeline settings");
  if (!(before.live == after.live) || !(before.truth == after.truth) ||
      before.time_offset_s != after.time_offset_s)
    say("settings");
  return said.empty() ? "the last edit" : said;
}

void AppState::RememberFolderOf(const std::string& file) {
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(file, ec);
  last_folder =
      (ec ? std::filesystem::path(file) : absolute).lexically_normal().parent_path().string();
  if (last_folder.empty() || last_folder.back() != '/') last_folder += '/';
}

void AppState::LoadRecent() {
  recent.clear();
  if (recent_file.empty()) return;
  std::ifstream in(recent_file);
  if (!in) return;
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    for (const auto& p : j.at("recent")) recent.push_back(p.get<std::string>());
    if (j.contains("last_folder")) last_folder = j.at("last_folder").get<std::string>();
  } catch (const std::exception&) {
    recent.clear();  // a damaged list is not worth an error
  }
}

void AppState::AddRecent(const std::string& path) {
  recent.erase(std::remove(recent.begin(), recent.end(), path), recent.end());
  recent.insert(recent.begin(), path);
  if (recent.size() > kMaxRecent) recent.resize(kMaxRecent);
  SaveRecent();
}

void AppState::RemoveRecent(const std::string& path) {
  const size_t before = recent.size();
  recent.erase(std::remove(recent.begin(), recent.end(), path), recent.end());
  if (recent.size() != before) SaveRecent();
}

void AppState::SaveRecent() const {
  if (recent_file.empty()) return;
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(recent_file).parent_path(), ec);
  WriteFileAtomic(recent_file,
                  nlohmann::json{{"recent", recent}, {"last_folder", last_folder}}.dump(2) + "\n");
}

Status MergeGroups(const std::vector<GroupSpec>& current, int num_triangles,
                   const std::set<int>& groups, std::vector<GroupSpec>* result) {
  GroupingEdit edit;
  edit.op = "merge";
  edit.groups.assign(groups.begin(), groups.end());
  return Apply(current, edit, num_triangles, result);
}

Status SplitTriangles(const std::vector<GroupSpec>& current, int num_triangles,
                      const std::set<int>& triangles, std::vector<GroupSpec>* result) {
  GroupingEdit edit;
  edit.op = "split";
  edit.triangles.assign(triangles.begin(), triangles.end());
  return Apply(current, edit, num_triangles, result);
}

Status MoveTriangles(const std::vector<GroupSpec>& current, int num_triangles,
                     const std::set<int>& triangles, int target_group,
                     std::vector<GroupSpec>* result) {
  GroupingEdit edit;
  edit.op = "move";
  edit.triangles.assign(triangles.begin(), triangles.end());
  edit.target_group = target_group;
  return Apply(current, edit, num_triangles, result);
}

Status SetGroupTexelSize(const std::vector<GroupSpec>& current, int num_triangles,
                         const std::set<int>& groups, double texel_size_m,
                         std::vector<GroupSpec>* result) {
  GroupingEdit edit;
  edit.op = "texel";
  edit.groups.assign(groups.begin(), groups.end());
  edit.texel_size_m = texel_size_m;
  return Apply(current, edit, num_triangles, result);
}

std::string DescribeGroupsSplitBack(const std::vector<GroupSpec>& stored,
                                    const std::vector<GroupSpec>& built, int num_triangles) {
  std::vector<int> built_of(num_triangles, -1);
  for (size_t g = 0; g < built.size(); ++g)
    for (int t : built[g].triangles)
      if (t >= 0 && t < num_triangles) built_of[t] = static_cast<int>(g);
  int split = 0, pieces = 0;
  std::string first;  // the first split group's numbers now, as the Grouping panel lists them
  for (size_t g = 0; g < stored.size(); ++g) {
    std::set<int> parts;
    for (int t : stored[g].triangles)
      if (t >= 0 && t < num_triangles && built_of[t] >= 0) parts.insert(built_of[t]);
    if (parts.size() < 2) continue;
    if (split == 0) {
      const std::vector<int> numbers(parts.begin(), parts.end());
      for (size_t k = 0; k < numbers.size(); ++k)
        first += std::string(k == 0                    ? ""
                             : k + 1 == numbers.size() ? " and "
                                                       : ", ") +
                 std::to_string(numbers[k]);
    }
    ++split;
    pieces += static_cast<int>(parts.size());
  }
  if (split == 0) return "";
  return "split back apart: " + std::to_string(split) + " stored group" +
         (split > 1 ? "s became " : " became ") + std::to_string(pieces) +
         " buffers while painting (" + (split > 1 ? "the first is now groups " : "now groups ") +
         first +
         "), because some of their triangles face away from the group's mean plane (they "
         "would fold over in one buffer); merge only surfaces that face the same way";
}

}  // namespace fresco
