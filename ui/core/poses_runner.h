// The app's COLMAP worker: on its own thread, runs COLMAP on the project's frames
// with the CLI's code (RunColmapOnProject, then VerifyPoses and WriteVerifyReport as
// `fresco poses verify`, and BootstrapFromColmap and WriteBootstrap as `fresco poses
// bootstrap`, from the same reconstruction), publishing a snapshot at every COLMAP step.
// A run can be cancelled (the running colmap program is stopped). Applying the
// bootstrapped poses is an undoable project edit. Headless: plain data, no ImGui.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "pipeline/core/project.h"
#include "pipeline/poses/bootstrap_run.h"
#include "pipeline/poses/project_colmap.h"
#include "pipeline/poses/verify.h"
#include "ui/core/app_state.h"

namespace fresco {

struct PosesRequest {
  Project project;      // as it was when the run was asked for
  std::string out_dir;  // COLMAP's workspace is OUT/colmap; verify.* and the bootstrap in OUT
  // every_n_frames, max_frames, scene_size_m, existing_model and colmap.{matcher,
  // max_image_size, max_num_features, threads} as the CLI's options; the rest is filled in.
  ProjectColmapOptions colmap;
  VerifyOptions verify;
  BootstrapOptions bootstrap;
  std::string control_points_file;  // "" = align with the given poses
};

struct PosesSnapshot {
  uint64_t version = 0;  // increases with every publish
  // "", "colmap 2/5: exhaustive_matcher", "done: ...", "cancelled", "error: ..."
  std::string status;
  bool busy = false;
  bool has_request = false;
  PosesRequest request;
  // Progress of the run under way: COLMAP steps started of `steps` (0 before COLMAP).
  int step = 0, steps = 0;
  std::string step_name;
  std::chrono::steady_clock::time_point started, step_started;
  // The running step's log (its progress lines: colmap_log_progress.h) and the images COLMAP
  // was given (read from the first step's log once it ran; 0: not known yet).
  std::string step_log;
  int step_images = 0;

  // The reconstruction (after a run).
  bool reconstructed = false;
  int frames = 0, registered = 0;
  double colmap_seconds = 0.0;
  std::vector<std::pair<std::string, double>> step_seconds;
  std::string matcher;     // "exhaustive" or "sequential" ("" for an earlier model)
  int frames_offered = 0;  // frames before keyframe selection
  int keyframes = 0;       // of them, sent to COLMAP's mapper (the others registered later)
  // The verification (`fresco poses verify`): per frame in verify.frames, and the frame's
  // index in the project's video (where the pipeline goes to show it).
  bool verified = false;
  std::string verify_error;  // why not, when reconstructed but not verified
  VerifyResult verify;
  std::vector<int> frame_index;
  // The bootstrap (`fresco poses bootstrap`), written to OUT: poses for the registered frames.
  bool bootstrapped = false;
  std::string bootstrap_error;  // why not, when reconstructed but not bootstrapped
  std::string bootstrap_poses;  // OUT/sparse/images.txt (absolute)
  std::string aligned_with;     // "given_poses" or "control_points"
  int bootstrap_inliers = 0, bootstrap_compared = 0;
  // The bootstrapped poses against the given ones: which are better (bootstrap_run.h).
  PosesComparison bootstrap_comparison;
};

class PosesRunner {
 public:
  PosesRunner();
  ~PosesRunner();  // stops a run under way

  // Starts a run (a run under way is cancelled first).
  void Run(const PosesRequest& request);
  void Cancel();
  void WaitIdle();  // tests, --screenshot
  std::shared_ptr<const PosesSnapshot> Snapshot() const;

 private:
  void Loop();
  void RunOnce(const PosesRequest& request);
  void Publish();

  mutable std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::deque<PosesRequest> queue_;
  bool busy_ = false, quit_ = false;
  std::atomic<bool> cancel_{false};
  std::shared_ptr<const PosesSnapshot> snapshot_;
  PosesSnapshot working_;  // worker only
  std::thread thread_;
};

// Points the project at the bootstrapped poses (`poses` = snap.bootstrap_poses), as an
// undoable edit that marks it dirty (AppState::BeginEdit). Errors: nothing bootstrapped, no
// project, or the run was made on another project file.
Status ApplyBootstrappedPoses(const PosesSnapshot& snap, AppState* state);

}  // namespace fresco
