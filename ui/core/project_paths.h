// The four paths a project names (scene, video, camera, poses) as the app edits them: typed
// paths (absolute, or relative to the working folder) turned into paths relative to the
// project file, the checks `fresco run` makes when it loads a project, and repairing an
// existing project file's paths in place. No ImGui: tests call these directly.
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/project.h"
#include "pipeline/core/status.h"
#include "ui/core/dropped_file.h"

namespace fresco {

struct ProjectPaths {
  std::string scene, video, camera, poses;
  bool operator==(const ProjectPaths& other) const {
    return scene == other.scene && video == other.video && camera == other.camera &&
           poses == other.poses;
  }
};

// A typed path as the project file at `project_file` (absolute) writes it: relative to its
// folder. URLs, "device:N", "builtin:NAME" and "" stay as typed; a folder's trailing '/'
// stays.
std::string PathRelativeTo(const std::string& typed, const std::string& project_file);

// The project's paths as the user edits them: resolved against the project file's folder
// (absolute), URLs and built-in scenes as written. A version-2 project: its first stream's.
ProjectPaths EditablePaths(const Project& project);

// The checks `fresco run` makes on loading a project whose text is `text` and whose file is
// `file`: the JSON loader, one video stream, then every file the project names (as
// LoadCapture reads them; a live video is not opened). The errors are the CLI's one-line
// "FILE: field: ..." messages. `require_poses` false: a poses file may hold none (poses about
// to be bootstrapped with COLMAP, as `fresco poses` reads a project).
Status CheckAsRunLoads(const std::string& text, const std::string& file, Project* parsed,
                       bool require_poses = true);

// The project the New project form makes from `typed`, to be saved as `project_file` (which
// must not exist yet): its paths relative to that file, checked as CheckAsRunLoads checks.
// Writes nothing; `parsed->file_path` is the absolute, normalised project file.
Status CheckNewProject(const ProjectPaths& typed, const std::string& project_file,
                       bool require_poses, Project* parsed);

// Repairs the project file `file` (absolute) in place: its scene, video, camera and poses
// become `typed` (relative to the file, as PathRelativeTo writes them; a version-2 file's
// one stream's keys), every other key and the keys' order stay as they are. Checked as
// CheckAsRunLoads checks; on an error nothing is written; else written atomically (temp
// file, then rename). `repaired`: the project as the file now loads.
Status RepairProjectPaths(const std::string& file, const ProjectPaths& typed, Project* repaired);

// The field of `paths` a dropped file of `kind` fills (nullptr for a project or unknown).
std::string* FieldFor(DroppedKind kind, ProjectPaths* paths);

// The entries of the folder a typed path is in (or of the typed folder), whose names start
// with what is typed after the last '/' and end with one of `extensions` (folders always),
// sorted; folders end in '/'.
std::vector<std::string> BrowseEntries(const std::string& typed,
                                       const std::vector<std::string>& extensions);
// The folder above the one a typed path lists ("a/" for "a/b/x", "../" for "x", "/" for
// "/usr/"), "" at the file system's root.
std::string ParentFolder(const std::string& typed);

}  // namespace fresco
