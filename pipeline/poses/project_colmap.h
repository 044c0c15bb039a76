// COLMAP on a project's frames: the frames as image files (a folder video is used in place;
// a video file's frames are exported to OUT/images/), the project's single camera held
// fixed, and each frame's given pose (if any) and COLMAP pose (if registered) side by side.
// The first stage of both `fresco poses verify` and `fresco poses bootstrap`.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "pipeline/core/capture.h"
#include "pipeline/core/project.h"
#include "pipeline/poses/colmap_runner.h"
#include "pipeline/poses/verify.h"

namespace fresco {

struct ProjectColmapOptions {
  std::string out_dir;     // the COLMAP workspace: OUT/database.db, sparse/, logs/, ...
  int every_n_frames = 1;  // use every Nth frame only
  int max_frames = 0;      // 0 = all (after every_n_frames)
  // Scene size (metres) used for thresholds; 0 = the diagonal of the scene's bounding box
  // (the scene is then loaded).
  double scene_size_m = 0.0;
  bool load_scene = false;  // load the scene even when scene_size_m is given (mesh ICP)
  // Keyframes of an ordered sequence (a video file, or a frame folder whose given poses
  // move little from frame to frame): a frame goes to COLMAP when its given pose has moved
  // at least keyframe_step_rel x scene size or turned at least keyframe_rotation_deg since
  // the last keyframe (the first and last frames, and frames without a given pose, always
  // do). 0 and 0 = every frame. Ordered sequences are matched sequentially (kAuto).
  double keyframe_step_rel = 0.005;
  double keyframe_rotation_deg = 2.0;
  // The frames between keyframes are then registered to the keyframes' reconstruction (each
  // matched with the two keyframes on either side of it), so that they are compared too.
  bool register_other_frames = true;
  ColmapRunOptions colmap;  // workspace, image_path, image_names, camera are filled in
  // A COLMAP text model folder from an earlier run (e.g. OUT/colmap/sparse_txt/0 of
  // `fresco poses verify`) to use instead of running COLMAP; "" = run COLMAP. Its images are
  // matched to the frames by name.
  std::string existing_model;
};

struct ProjectColmapFrame {
  std::string name;                    // image file name, as COLMAP knows it
  int index = 0;                       // the frame's index in the project's video
  const PosedImage* given = nullptr;   // into ProjectColmap::capture.poses
  const PosedImage* colmap = nullptr;  // into ProjectColmap::run.model.images
  bool keyframe = true;  // reconstructed by the mapper (else registered to it afterwards)
};

struct ProjectColmap {
  Capture capture;
  Camera camera;
  double scene_size_m = 0.0;
  std::vector<ProjectColmapFrame> frames;  // in sequence order (keyframes and others)
  ColmapRunResult run;
};

// True when the centres look like a sequence: the median step between neighbours is under a
// third of the median distance between any two (at least 3 centres).
bool CentresLookOrdered(const std::vector<Eigen::Vector3d>& centres);

// The keyframes among `poses` (nullptr: no given pose), as ProjectColmapOptions says;
// indices in order.
std::vector<int> SelectKeyframes(const std::vector<const Rigid3d*>& poses, double step_m,
                                 double rotation_deg);

// Loads the project's capture, writes the frames when needed and runs COLMAP. Input errors
// (project, camera, video, an earlier model) are bad input; COLMAP's own errors, prefixed
// with "colmap", are failed work (StatusKind::kFailed).
Status RunColmapOnProject(const Project& project, const ProjectColmapOptions& options,
                          ProjectColmap* result);

// The frames as VerifyPoses takes them (pointing into `colmap`).
std::vector<VerifyFrameInput> VerifyInputs(const ProjectColmap& colmap);

}  // namespace fresco
