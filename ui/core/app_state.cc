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

}  // namespace

Status AppState::Open(const std::string& path) {
  Project loaded;
  FRESCO_RETURN_IF_ERROR(LoadProject(path, {}, &loaded));
  FRESCO_RETURN_IF_ERROR(CheckOneStream(loaded, "the app"));
  // The app edits one stream as version-1 keys: a version-2 file's one stream is saved back
  // as version 1 (the same project).
  loaded = loaded.ForStream(0);
  project = loaded;
  has_project = true;
  dirty = false;
  undo.clear();
  redo.clear();
  selected_groups.clear();
  selected_triangles.clear();
  AddRecent(loaded.file_path);
  message = "opened " + loaded.file_path;
  return Status::Ok();
}

Status AppState::Save(const std::string& path) {
  if (!has_project) return Status::Error("no project to save");
  const std::string target = path.empty() ? project.file_path : path;
  FRESCO_RETURN_IF_ERROR(SaveProject(project, target));
  // Re-read what was written, so paths are as they resolve from the new place.
  Project saved;
  FRESCO_RETURN_IF_ERROR(LoadProject(target, {}, &saved));
  project = saved;
  dirty = false;
  AddRecent(saved.file_path);
  message = "saved " + saved.file_path;
  return Status::Ok();
}

void AppState::BeginEdit() {
  undo.push_back(project);
  if (undo.size() > kMaxUndo) undo.erase(undo.begin());
  redo.clear();
  dirty = true;
}

bool AppState::Undo() {
  if (undo.empty()) return false;
  redo.push_back(project);
  project = undo.back();
  undo.pop_back();
  dirty = true;
  return true;
}

bool AppState::Redo() {
  if (redo.empty()) return false;
  undo.push_back(project);
  project = redo.back();
  redo.pop_back();
  dirty = true;
  return true;
}

void AppState::LoadRecent() {
  recent.clear();
  if (recent_file.empty()) return;
  std::ifstream in(recent_file);
  if (!in) return;
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    for (const auto& p : j.at("recent")) recent.push_back(p.get<std::string>());
  } catch (const std::exception&) {
    recent.clear();  // a damaged list is not worth an error
  }
}

void AppState::AddRecent(const std::string& path) {
  recent.erase(std::remove(recent.begin(), recent.end(), path), recent.end());
  recent.insert(recent.begin(), path);
  if (recent.size() > kMaxRecent) recent.resize(kMaxRecent);
  if (recent_file.empty()) return;
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(recent_file).parent_path(), ec);
  WriteFileAtomic(recent_file, nlohmann::json{{"recent", recent}}.dump(2) + "\n");
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

}  // namespace fresco
