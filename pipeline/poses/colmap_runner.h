// Runs COLMAP (the `colmap` program; Debian ships no library) headless on the CPU over a set
// of images seen by one camera whose intrinsics are held fixed, and reads back its largest
// reconstruction. Steps, each logged to WORKSPACE/logs/NN_STEP.log, and every command line
// appended to WORKSPACE/commands.txt (so a run can be repeated by hand):
//   feature_extractor (single camera, the given intrinsics, --SiftExtraction.use_gpu 0)
//   exhaustive_matcher or sequential_matcher (loop detection off: Debian has no vocab tree)
//   mapper (ba_refine_focal_length/principal_point/extra_params 0)
//   model_converter (each model to TXT under WORKSPACE/sparse_txt/N), then the one with the
//   most registered images is read (ColmapModel, Fresco's (0,0) pixel convention)
// and, with `register_names` (the frames between keyframes), those registered to it:
//   feature_extractor (the same camera), matches_importer (each with the keyframes beside
//   it, `register_pairs`), image_registrator (into WORKSPACE/sparse_registered, no bundle
//   adjustment: the keyframes' reconstruction stays as it was), model_converter
//   (WORKSPACE/sparse_txt/registered), read instead.
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "pipeline/core/camera.h"
#include "pipeline/core/poses.h"
#include "pipeline/core/status.h"

namespace fresco {

enum class ColmapMatcher { kAuto, kExhaustive, kSequential };

struct ColmapRunOptions {
  // The program: a path or a name looked up on PATH. "" = `colmap` on PATH, else the one
  // found when Fresco was configured (COLMAP_EXECUTABLE).
  std::string program;
  std::string workspace;                 // output folder (created)
  std::string image_path;                // folder holding the images
  std::vector<std::string> image_names;  // relative to image_path; all images when empty
  Camera camera;                         // intrinsics, held fixed ((0,0) convention)
  // kAuto: sequential when the images are `ordered` (video frames: each is matched with its
  // next `sequential_overlap` ones, minutes instead of hours on long sequences); else
  // exhaustive up to `exhaustive_max_images` images, sequential beyond.
  ColmapMatcher matcher = ColmapMatcher::kAuto;
  bool ordered = false;  // the images are a sequence (neighbours in time see the same things)
  int exhaustive_max_images = 60;
  int sequential_overlap = 10;  // sequential: each image is matched with this many next ones
  // SiftExtraction.max_image_size: images are downscaled to this longest side for feature
  // extraction (keypoints are scaled back). 0 = COLMAP's default (3200).
  int max_image_size = 0;
  int max_num_features = 0;  // SiftExtraction.max_num_features; 0 = COLMAP's default (8192)
  int threads = 0;           // num_threads of every step; 0 = all cores
  int min_registered = 3;    // fewer registered images is an error
  // Images (relative to image_path) registered to the reconstruction once it is made, each
  // matched only with the images `register_pairs` pairs it with (its keyframes).
  std::vector<std::string> register_names;
  std::vector<std::pair<std::string, std::string>> register_pairs;
  // Called before each step: (step name, index from 0, number of steps).
  std::function<void(const std::string& step, int index, int total)> progress;
  // When set and it becomes true, the running step is stopped and RunColmap fails with
  // "colmap: cancelled" (the app's Poses panel).
  const std::atomic<bool>* cancel = nullptr;
};

struct ColmapRunResult {
  ColmapModel model;  // the reconstruction with the most registered images
  int registered = 0;
  int models = 0;  // reconstructions the mapper made
  std::string program;
  std::string matcher;  // "exhaustive" or "sequential"; "" for an earlier run's model
  // Frames of the project offered (after every_n_frames/max_frames) and the keyframes among
  // them that COLMAP was given (RunColmapOnProject fills these; 0 = not selected).
  int frames_offered = 0, keyframes = 0;
  int registered_later = 0;    // of `register_names`, those image_registrator registered
  std::string register_error;  // why they were not (the keyframes' reconstruction is kept)
  double seconds = 0.0;
  std::vector<std::pair<std::string, double>> step_seconds;  // wall time of each step
};

// The `colmap` program to use for `program` (see ColmapRunOptions::program); "" when none.
std::string FindColmap(const std::string& program);

// Runs the steps. Errors: colmap missing, a step that failed (names it and its log), no
// reconstruction, fewer than `min_registered` images registered.
Status RunColmap(const ColmapRunOptions& options, ColmapRunResult* result);

}  // namespace fresco
