// A new project whose poses are bootstrapped with COLMAP (the New project form's "bootstrap
// with COLMAP", for a video and a mesh without poses): the form's paths are checked as for
// any new project, COLMAP runs on the frames in the app's COLMAP worker (PosesRunner: the
// code of `fresco poses bootstrap`, with its progress and cancel) in a fresh workspace in
// the temp folder, and the bootstrapped poses are placed on the mesh by control points (or
// by rough poses). Only when all of it succeeded are they written beside the new project as
// PROJECT_DIR/poses.txt (COLMAP images.txt, temp file then rename) and the project saved
// pointing at them; on any failure nothing is written there. Headless: tests call these.
//
//   NewProjectBootstrap boot;
//   PrepareNewProjectBootstrap(form, file, options, &boot);  // checks; nothing written
//   runner.Run(boot.request);  ... until !runner.Snapshot()->busy
//   FinishNewProjectBootstrap(boot, *runner.Snapshot(), &project);  // writes, or explains
#pragma once

#include <string>

#include "pipeline/core/project.h"
#include "pipeline/core/status.h"
#include "ui/core/poses_runner.h"
#include "ui/core/project_paths.h"

namespace fresco {

// The app's SIFT features per image (New project's bootstrap and the Poses panel): the
// guide's advice, much faster than COLMAP's default 8192 and enough for most captures.
constexpr int kAppMaxFeatures = 2000;

struct NewProjectBootstrapOptions {
  // >= 3 known points on the mesh and where frames see them (pipeline/poses/bootstrap.h's
  // file: NAME X Y Z IMAGE U V [IMAGE U V ...]) that place COLMAP's reconstruction on the
  // mesh; "" = place it by the rough poses of the form's Poses field instead.
  std::string control_points;
  bool refine_mesh = false;            // then fit COLMAP's sparse points to the mesh (ICP)
  int max_features = kAppMaxFeatures;  // SIFT features per image; 0 = COLMAP's default (8192)
  int max_image_size = 0;              // longest side for feature extraction; 0 = COLMAP's (3200)
  std::string colmap_program;          // "" = `colmap` on PATH
};

// The file the bootstrapped poses go to, beside the project file.
inline constexpr const char* kBootstrappedPosesName = "poses.txt";

struct NewProjectBootstrap {
  std::string project_file;  // absolute: where the project is saved
  std::string poses_file;    // absolute: PROJECT_DIR/poses.txt
  // COLMAP's workspace (a fresh folder in the temp folder): removed when the bootstrap
  // succeeded, was cancelled or never ran COLMAP; kept when COLMAP failed, for its logs (the
  // error names them).
  std::string workspace;
  PosesRequest request;  // for PosesRunner::Run
};

// Checks the form as Create checks any new project (CheckNewProject; a poses field left
// empty is allowed here), then what the bootstrap needs: a video file or frame folder (not
// a live URL), readable control points or rough poses from a file, and PROJECT_DIR/poses.txt
// free. Makes the workspace; writes nothing beside the project. Errors name the field.
Status PrepareNewProjectBootstrap(const ProjectPaths& typed, const std::string& project_file,
                                  const NewProjectBootstrapOptions& options,
                                  NewProjectBootstrap* bootstrap);

// After the run (`done`: the runner's snapshot once it is no longer busy): writes the
// bootstrapped poses to `poses_file`, saves the project pointing at them (checked as `fresco
// run` loads it) and returns it in `project`, with `summary` one line on how the poses were
// made ("16 of 16 frames posed by COLMAP, placed by 5 control points"). Errors: one message
// naming the cause (COLMAP missing, too few frames registered, cancelled, the placement);
// then nothing is written beside the project (folders it made are removed). Removes the
// workspace as NewProjectBootstrap::workspace says.
Status FinishNewProjectBootstrap(const NewProjectBootstrap& bootstrap, const PosesSnapshot& done,
                                 Project* project, std::string* summary);

// Removes the workspace (a bootstrap abandoned before it finished: the app closed).
void DiscardNewProjectBootstrap(const NewProjectBootstrap& bootstrap);

}  // namespace fresco
