// What the user edits in the app: the project (its path, whether it has unsaved changes,
// undo/redo of its grouping and settings), the recently opened projects, and what is
// selected. Plain data and file operations, no ImGui and no GL: tests drive it directly.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "pipeline/core/project.h"
#include "pipeline/core/status.h"
#include "ui/core/project_paths.h"

namespace fresco {

struct AppState {
  Project project;  // as edited
  bool has_project = false;
  bool dirty = false;               // differs from the file since it was opened or saved
  Project saved;                    // the project as its file holds it (Open, Save)
  std::string message;              // the last status or error, shown in the status bar
  std::vector<std::string> recent;  // most recent first
  std::string recent_file;          // where `recent` is kept ("" = not kept)
  // The folder last used (absolute, ending in '/'; "" = none yet): where a path list ("..."
  // beside a path) was last used, or the folder of the project last opened or saved. An
  // empty field's list starts there. Kept with `recent`.
  std::string last_folder;

  // Selection (viewport picks and the grouping table).
  std::set<int> selected_triangles;
  std::set<int> selected_groups;

  // Actions waiting for the unsaved-changes prompt: a project to open, or quitting.
  std::string pending_open;
  // Said after "opened PENDING_OPEN" once it opens (how a new project's poses were made).
  std::string pending_open_note;
  bool pending_quit = false;

  // Undo/redo over whole project snapshots (settings, grouping and path edits).
  std::vector<Project> undo, redo;

  // The project that did not open because a file it names is missing (the last Open's, as
  // its file reads; cleared by the next Open): the Project panel edits its paths, and
  // RepairPaths writes them, after which it opens.
  Project unopened;
  bool has_unopened = false;

  // Opens a project (errors leave the current one as it was).
  Status Open(const std::string& path);
  // Saves atomically to the project's path, or to `path` when given (Save As).
  Status Save(const std::string& path = "");
  // Call before changing `project`: records an undo step and marks the project dirty.
  void BeginEdit();
  // Writes `typed` as the scene, video, camera and poses of the project that did not open
  // (when there is one) or of the open project, checked as `fresco run` loads a project and
  // atomically, every other key of the file unchanged (RepairProjectPaths); on an error
  // nothing changes. The open project's paths change as an undoable edit (its other unsaved
  // edits stay unsaved); a project that did not open is then ready to Open (`*file`).
  Status RepairPaths(const ProjectPaths& typed, std::string* file);
  // Undo and redo say what they changed back in `message` (DescribeProjectChange), so the
  // status bar never keeps describing an edit that was undone; the project is unsaved after
  // them only when it differs from `saved` (Ctrl+Z back to the saved state is not an edit).
  bool Undo();
  bool Redo();

  // `last_folder` becomes the folder of `file` (absolute).
  void RememberFolderOf(const std::string& file);
  void LoadRecent();
  void SaveRecent() const;  // to recent_file (when set)
  void AddRecent(const std::string& path);
  void RemoveRecent(const std::string& path);  // a project that failed to open
};

// What differs between two versions of the project, as undo and redo say it: with `to`
// "back to", "camera back to cameras.txt"; "the grouping", ... ("the last edit" when nothing
// differs).
std::string DescribeProjectChange(const Project& before, const Project& after,
                                  const std::string& to);

// Grouping edits as the app makes them: on the groups the current session built (one per
// base buffer), stored in the project as explicit groups (grouping.groups) so that
// `fresco run` paints exactly what the app shows. `num_triangles`: the scene's. Errors name
// the group or triangle.
Status MergeGroups(const std::vector<GroupSpec>& current, int num_triangles,
                   const std::set<int>& groups, std::vector<GroupSpec>* result);
Status SplitTriangles(const std::vector<GroupSpec>& current, int num_triangles,
                      const std::set<int>& triangles, std::vector<GroupSpec>* result);
Status MoveTriangles(const std::vector<GroupSpec>& current, int num_triangles,
                     const std::set<int>& triangles, int target_group,
                     std::vector<GroupSpec>* result);
Status SetGroupTexelSize(const std::vector<GroupSpec>& current, int num_triangles,
                         const std::set<int>& groups, double texel_size_m,
                         std::vector<GroupSpec>* result);

// Why the painting shows more groups than the project stores, or "" when it does not: a
// stored group (a merge, typically) whose triangles fold over on its own projection plane
// is split back apart when the buffers are built (BuildBaseBuffers). `stored`: the
// project's explicit groups; `built`: the session's groups (one per base buffer). The split
// group is named by its numbers in `built` (what the Grouping panel lists after the split).
std::string DescribeGroupsSplitBack(const std::vector<GroupSpec>& stored,
                                    const std::vector<GroupSpec>& built, int num_triangles);

}  // namespace fresco
