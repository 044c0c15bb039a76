// A project opened for painting, ready for a PaintRun (paint_run.h): every stream's capture
// (scene, cameras, poses, video), the PaintSession over the scene, and the source of its
// posed frames: files read ahead (file_frame_source.h), or the live inputs
// (live_frame_source.h) for a live stream; several streams of which one is live are merged as
// their frames arrive (merged_frame_source.h). The one way to open a project for painting:
// `fresco run`, bench, rephoto, eval and the app's worker all open their projects here.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "pipeline/core/capture.h"
#include "pipeline/core/project.h"
#include "pipeline/live/live_input.h"
#include "pipeline/paint/joint_pose_adjustment.h"
#include "pipeline/paint/mover_masks.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/run/posed_frame_source.h"
#include "pipeline/run/shard.h"

namespace fresco {

class DecodedFrames;  // file_frame_source.h

// The steps of opening a project that PaintJobOptions::step_started names.
inline constexpr const char* kLoadStep = "loading the scene, poses and buffers";
inline constexpr const char* kCamerasStep = "preparing the cameras";

struct PaintJobOptions {
  // Non-empty: the project must have one stream, else an error naming `streams` and this
  // ("fresco bench").
  std::string one_stream_for;
  // Live projects: keep every tracker pose (a recording writes them; LiveInputs).
  bool keep_tracker_poses = false;
  // Live projects: >= 0: the source's Next waits at most this long for a frame, then says
  // kWaiting (the app's worker, which has commands to answer meanwhile); < 0: Next waits for
  // a frame or the end (`fresco run`).
  int poll_ms = -1;
  // pipeline.refine.joint: progress of the poses' adjustment before painting (optional).
  std::function<void(int done, int total, const std::string& line)> joint_progress;
  // Captures from files with background `auto` or a model: progress of the search for movers
  // across views before painting, pass by pass (optional).
  std::function<void(int done, int total, const std::string& line)> movers_progress;
  // The whole-capture pre-pass (refine.joint or the movers' search): its reading of every
  // frame, called after each frame read with the frames read and the frames to read (-1:
  // unknown) (optional).
  std::function<void(int done, int total, const std::string& line)> read_progress;
  // Before each step of opening without a progress of its own (kLoadStep, kCamerasStep),
  // naming it (optional).
  std::function<void(const std::string& step)> step_started;
  // pipeline.refine.joint: frames held out of painting (as PaintRunOptions' holdout_every and
  // holdout_counter, by position in reading order) take no part in the adjustment and keep
  // their given poses: the photos `fresco rephoto` and `fresco bench` score are not used.
  int joint_holdout_every = 0;
  int joint_holdout_counter = -1;
  // Checked between the frames the whole-capture pre-pass reads (pipeline.refine.joint,
  // movers across views); true: OpenPaintJob stops with the error "PROJECT: interrupted"
  // (optional; a run's stop is PaintRunHooks::stop).
  std::function<bool()> stop;
  // Paint at the project's true poses (truth.poses, as a synthetic capture has them) instead
  // of its given ones: what exact poses would give (`fresco eval --recovery`). A pose without
  // a true one of its name keeps the given pose.
  bool paint_at_truth_poses = false;
  // Paint only shard `shard.index` of `shard.count` (shard.h; captures from files only): the
  // session paints that shard's buffers and the source skips, unread, the frames whose view
  // meets none of them (folders: unread; video files: grabbed, not converted to BGR).
  ShardSpec shard;
  // Non-empty (captures from files): the whole-capture pre-pass's outcome is read from this
  // file (prepass_file.h) instead of being found again; when the file does not exist, the
  // pre-pass runs and writes it. So the shards of one project run it once.
  std::string prepass_file;
  // Only the pre-pass file is wanted (`fresco run --prepass-only`): the charts are laid out,
  // not built (PaintSessionInputs::layout_only); the job paints nothing.
  bool prepass_only = false;
  // Decode the frames without a pose too (the app shows them); false: folders' frames without
  // a pose come out without pixels, undecoded (nothing paints them).
  bool read_frames_without_pose = false;
};

struct PaintJob {
  bool live = false;              // some stream is live
  std::vector<Capture> captures;  // one per stream (Project::Streams()); the scene in [0]
  std::unique_ptr<PaintSession> session;
  // One per stream; a file stream's is empty (no frames).
  std::vector<LiveInputs> live_inputs;
  std::unique_ptr<PosedFrameSource> source;
  // pipeline.refine.joint: what the joint adjustment of the poses did before painting.
  std::optional<PoseAdjustResult> joint_poses;
  // background.mode auto: the movers found across views before painting, which decided it
  // (`masks` is empty).
  std::optional<MoverMaskResult> mover_masks;
  // The decisions the whole-capture pre-pass handed the session (what prepass_file.h keeps):
  // refine.mode auto's pose check (SetRefinePoseCheck: ratio, threshold, frames) and
  // background.mode auto's movers across views (DecideBackgroundAcrossViews: fraction, frames).
  struct PrepassDecisions {
    bool ran = false;  // the pre-pass ran (or was read): poses and movers are its
    std::optional<std::tuple<double, double, int>> pose_check;
    std::optional<std::pair<double, int>> background_across_views;
  } prepass;
  // The frames the whole-capture pre-pass decoded, kept for painting to take (up to
  // 256 MB; folders only; null without a pre-pass).
  std::shared_ptr<DecodedFrames> decoded;
  // Sharded (PaintJobOptions::shard): the shard of every buffer (AssignBuffersToShards).
  std::vector<int> buffer_shard;
  // Sharded: this shard's work as the assignment counted it, and its CPU seconds as estimated.
  ShardWork shard_work;
  double shard_estimated_s = 0;
  // Where opening the job spent its wall time, seconds (what a user waits for before the
  // first frame paints; `fresco run` reports them in metrics.json's "wall").
  struct OpenSeconds {
    double load = 0;      // scene, cameras, poses read; charts and base buffers built
    double cameras = 0;   // each camera's ray table and the mesh's culling clusters
    // The whole-capture pre-pass runs while the charts and buffers are built: its steps overlap
    // `load`.
    double read = 0;      // the whole-capture pre-pass: every frame read and decoded once
    double prepass_file = 0;  // ... or its outcome read from (or written to) prepass_file
    double joint = 0;     // ... the poses adjusted together (refine.joint)
    double movers = 0;    // ... the movers found across views (background auto / across_views)
    double connect = 0;   // live sources connected
    double total = 0;
  } open_seconds;

  const Scene& scene() const { return captures[0].scene; }
};

// True when stream `index` of `project` is live (its video or its poses).
bool IsLiveStream(const Project& project, int index);

// Loads and checks every input, builds the session and opens the source (live sources
// connect here, all streams at once). Errors are bad input (exit 2), naming the file and
// field.
Status OpenPaintJob(const Project& project, const PaintJobOptions& options,
                    std::unique_ptr<PaintJob>* job);

}  // namespace fresco
