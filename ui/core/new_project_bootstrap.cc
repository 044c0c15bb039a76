#include "ui/core/new_project_bootstrap.h"

#include <stdlib.h>  // mkdtemp

#include <cstdio>
#include <filesystem>
#include <vector>

#include "pipeline/core/atomic_file.h"
#include "pipeline/poses/bootstrap.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

constexpr const char* kWhat = "bootstrap with COLMAP";

Status MakeWorkspace(std::string* path) {
  std::error_code ec;
  std::string pattern = (fs::temp_directory_path(ec) / "fresco-new-project-XXXXXX").string();
  if (ec || mkdtemp(pattern.data()) == nullptr)
    return Status::Error(pattern + ": cannot make COLMAP's workspace in the temp folder");
  *path = pattern;
  return Status::Ok();
}

void RemoveAll(const std::string& path) {
  std::error_code ec;
  if (!path.empty()) fs::remove_all(path, ec);
}

// The checks that need the workspace (the placeholder poses file lives there).
Status CheckInWorkspace(const ProjectPaths& typed, const std::string& project_file,
                        const NewProjectBootstrapOptions& options, NewProjectBootstrap* b) {
  ProjectPaths checked = typed;
  if (typed.poses.empty()) {
    // The project COLMAP runs on names a poses file: one that holds none (as `fresco poses
    // bootstrap` reads a project without poses).
    checked.poses = (fs::path(b->workspace) / "no-poses.txt").string();
    FRESCO_RETURN_IF_ERROR(
        WriteFileAtomic(checked.poses, "# no poses: bootstrapped with COLMAP\n"));
  }
  // Rough poses that place the reconstruction must hold some.
  const bool poses_place_it = options.control_points.empty();
  Project parsed;
  FRESCO_RETURN_IF_ERROR(CheckNewProject(checked, project_file, poses_place_it, &parsed));
  const std::string video = parsed.Streams()[0].video;
  if (IsUrlOrDevice(video))
    return Status::Error(parsed.file_path + ": video: " + kWhat +
                         " needs a video file or a frame folder, not a live source (" + video +
                         ")");
  b->project_file = parsed.file_path;
  b->poses_file = (fs::path(parsed.file_path).parent_path() / kBootstrappedPosesName).string();
  std::error_code ec;
  if (fs::exists(b->poses_file, ec))
    return Status::Error(b->poses_file + ": exists already (the bootstrapped poses go there): " +
                         "save the project in another folder");

  PosesRequest& r = b->request;
  r.project = std::move(parsed);
  r.out_dir = b->workspace;
  r.control_points_file =
      options.control_points.empty()
          ? std::string()
          : fs::absolute(options.control_points, ec).lexically_normal().string();
  r.bootstrap.refine_mesh = options.refine_mesh;
  r.colmap.load_scene = options.refine_mesh;
  r.colmap.colmap.program = options.colmap_program;
  r.colmap.colmap.max_num_features = options.max_features;
  r.colmap.colmap.max_image_size = options.max_image_size;
  return Status::Ok();
}

// Where MakeDirectories(folder) starts making folders: its first missing ancestor ("" when
// it exists).
std::string FirstMissingFolder(const fs::path& folder) {
  std::error_code ec;
  std::string missing;
  for (fs::path p = folder; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    missing = p.string();
    if (p == p.parent_path()) break;
  }
  return missing;
}

// The bootstrapped poses beside the project, then the project: both or neither.
Status WriteProjectAndPoses(const NewProjectBootstrap& b, const PosesSnapshot& done,
                            Project* project) {
  std::string poses_text;
  FRESCO_RETURN_IF_ERROR(ReadFileToString(done.bootstrap_poses, &poses_text));
  std::error_code ec;
  for (const std::string& file : {b.project_file, b.poses_file})
    if (fs::exists(file, ec)) return Status::Error(file + ": exists already");
  Project out = done.request.project;
  out.poses = kBootstrappedPosesName;  // relative to the project file
  const fs::path folder = fs::path(b.project_file).parent_path();
  const std::string made = FirstMissingFolder(folder);
  Status s = MakeDirectories(folder.string());
  if (s.ok()) s = WriteFileAtomic(b.poses_file, poses_text);
  Project parsed;
  if (s.ok()) s = CheckAsRunLoads(ProjectToJsonText(out), b.project_file, &parsed);
  if (s.ok()) s = SaveProject(parsed, b.project_file);
  if (!s.ok()) {
    fs::remove(b.poses_file, ec);
    RemoveAll(made);
    return s;
  }
  *project = std::move(parsed);
  return Status::Ok();
}

std::string Summary(const PosesSnapshot& done) {
  char line[200];
  std::snprintf(line, sizeof(line), "%d of %d frames posed by COLMAP in %.0f s, ", done.registered,
                done.frames, done.colmap_seconds);
  std::string summary = line;
  if (done.aligned_with == "control_points") {
    summary += "placed on the mesh by control points";
  } else {
    std::snprintf(line, sizeof(line), "placed by the rough poses (%d of %d support the fit)",
                  done.bootstrap_inliers, done.bootstrap_compared);
    summary += line;
  }
  return summary;
}

}  // namespace

Status PrepareNewProjectBootstrap(const ProjectPaths& typed, const std::string& project_file,
                                  const NewProjectBootstrapOptions& options,
                                  NewProjectBootstrap* bootstrap) {
  *bootstrap = NewProjectBootstrap();
  if (IsUrlOrDevice(typed.poses))
    return Status::Error(std::string("poses: ") + kWhat +
                         " places its poses with control points or rough poses from a file, "
                         "not a live feed (" +
                         typed.poses + ")");
  if (options.control_points.empty() && typed.poses.empty())
    return Status::Error(std::string("control points: ") + kWhat +
                         " needs at least 3 known points on the mesh (or rough poses in the "
                         "Poses field) to place its reconstruction on the mesh");
  if (!options.control_points.empty()) {
    std::vector<ControlPoint> points;
    FRESCO_RETURN_IF_ERROR(ReadControlPoints(options.control_points, &points));
  }
  NewProjectBootstrap b;
  FRESCO_RETURN_IF_ERROR(MakeWorkspace(&b.workspace));
  if (Status s = CheckInWorkspace(typed, project_file, options, &b); !s.ok()) {
    RemoveAll(b.workspace);
    return s;
  }
  *bootstrap = std::move(b);
  return Status::Ok();
}

Status FinishNewProjectBootstrap(const NewProjectBootstrap& bootstrap, const PosesSnapshot& done,
                                 Project* project, std::string* summary) {
  Status s = Status::Ok();
  bool keep_workspace = false;
  if (!done.has_request || done.busy) {
    s = Status::Error(std::string(kWhat) + ": the run has not finished");
  } else if (done.status == "cancelled") {
    s = Status::Error(std::string(kWhat) + ": cancelled; no project was written");
  } else if (!done.reconstructed) {
    const std::string why =
        done.status.rfind("error: ", 0) == 0 ? done.status.substr(7) : done.status;
    // A COLMAP step that failed names its log in the workspace: keep it to be read.
    keep_workspace = why.find(bootstrap.workspace) != std::string::npos;
    s = Status::Error(std::string(kWhat) + ": " + why + "; no project was written");
  } else if (!done.bootstrapped) {
    s = Status::Error(std::string(kWhat) + ": COLMAP posed " + std::to_string(done.registered) +
                      " of " + std::to_string(done.frames) +
                      " frames, but they could not be placed on the mesh: " + done.bootstrap_error +
                      "; no project was written");
  } else {
    s = WriteProjectAndPoses(bootstrap, done, project);
    if (s.ok()) *summary = Summary(done);
  }
  if (!keep_workspace) DiscardNewProjectBootstrap(bootstrap);
  return s;
}

void DiscardNewProjectBootstrap(const NewProjectBootstrap& bootstrap) {
  RemoveAll(bootstrap.workspace);
}

}  // namespace fresco
