// The app's painting worker: owns the project's capture and PaintSession on its own thread
// and publishes immutable snapshots (the latest frame's report, debug images, painted
// buffers, timings, misalignment) that the panels read. The UI never waits for painting:
// commands (play, pause, step, seek, restart with new settings) are queued and the worker
// picks them up between frames. Settings are copied in on Restart, never shared.
//
// The worker opens and paints the project as `fresco run` does (pipeline/run: OpenPaintJob
// with its whole-capture pre-pass, PaintRun with its frame policy), so the analyst reviews
// what the replay produces. A project whose video or poses are live (device:N, udp://..., a
// TUM pose feed) has its live source polled: the worker waits for frames a little at a time,
// so it stays responsive and keeps publishing the sources' state (RunnerSnapshot::live,
// read by LiveWatch) when a source stalls or dies; Record() writes the session as a project
// to replay (LiveRecording).
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/core/camera.h"
#include "pipeline/core/project.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/scene.h"
#include "pipeline/paint/stage_report.h"
#include "pipeline/run/live_status.h"
#include "pipeline/run/paint_job.h"
#include "pipeline/run/paint_run.h"
#include "pipeline/run/run_snapshots.h"

namespace fresco {

// What does not change while one session paints: the model with its buffers' UVs, and the
// grouping (one group per base buffer).
struct SessionGeometry {
  Scene painted_layout;                 // PaintSession::PaintedSceneByBuffer() of the fresh session
  std::vector<int> buffer_of_triangle;  // (T) base buffer of each triangle, -1 for none
  std::vector<GroupSpec> groups;        // one per base buffer, as the session built them
  std::vector<int> buffer_texels;       // on-surface texels per buffer
  std::vector<double> buffer_texel_size_m;  // each buffer's texel edge (coarser where capped)
  std::vector<int64_t> buffer_size_texels;  // each buffer's width x height, gutter included
  std::vector<Rigid3d> path;                // cam_from_world of every posed frame, in order
  Camera camera;                            // the first camera (frustum drawing, preview)
  // Per stream (Project::Streams(); `path` and `camera` are stream 0's): its posed frames'
  // cam_from_world in order, and its first camera.
  std::vector<std::vector<Rigid3d>> stream_paths;
  std::vector<Camera> stream_cameras;
  int num_frames = 0;  // frames of all streams when known, else -1 (live)
  double texel_size_m = 0;
  int folds_split = 0;
};

struct RunnerSnapshot {
  uint64_t version = 0;  // increases with every publish
  uint64_t geometry_version = 0;
  std::shared_ptr<const SessionGeometry> geometry;  // null until a session opened
  std::string status;                               // "paused", "playing", "error: ..."
  // A step of opening under way ("adjusting poses 120/246", "loading the scene, ..."): the
  // status began with `step_text` when it started (at `step_started`) or last said how far it
  // got (`step_fraction` done, -1 when it does not say). The worker publishes only then, so
  // the window counts the time itself (StatusText), which would stand still in `status`.
  std::string step_text;
  double step_fraction = -1;
  std::chrono::steady_clock::time_point step_started;
  bool playing = false;
  int frame = -1;  // index of the frame last painted
  // A seek under way: the frame it paints up to (`frame` says how far it got; -1 while a
  // seek back goes back); -1 when none.
  int seek_target = -1;
  // The frame the last seek painted from: forward, the one after the frame shown; back, the
  // frame of the saved state it went back to (RunSnapshots; 0 when it reopened the project).
  int seek_from = -1;
  // A seek back under way, while it goes back (`frame` -1): the frame of the saved state it
  // restores (the state before that frame), -1 when it reopens the project instead.
  int seek_state = -1;
  std::string frame_name;
  bool has_pose = false;
  Rigid3d cam_from_world;
  cv::Mat frame_bgr;                   // the input frame
  int stream = 0;                      // ... its stream
  std::vector<cv::Mat> stream_frames;  // per stream, its latest input frame shown (or empty)
  FrameReport report;                  // stages with metrics and debug images
  // `report`'s frame was painted with debug images (a frame shown: paused, stepped or sought
  // to); false for one painted while playing between two publishes.
  bool report_has_images = false;
  std::shared_ptr<const std::vector<cv::Mat>> painted;  // per buffer BGRA (alpha 0 = never)
  // View-dependent layers (pipeline.layers), published with `painted`: each layer's mean
  // camera centre (the scene's local frame) and its buffers (BGRA); null or empty when off.
  struct LayerImages {
    Eigen::Vector3f centre_local = Eigen::Vector3f::Zero();
    std::vector<cv::Mat> bgra;
  };
  std::shared_ptr<const std::vector<LayerImages>> layers;
  uint64_t painted_version = 0;
  double coverage = 0;
  // The painting job's counts so far (frames read, painted, without a pose), as `fresco run`
  // counts them (pipeline/run/paint_run.h).
  PaintRunStats run;
  // Per painted frame, in order: stage wall times, and the misalignment figure (mean
  // absolute grey difference between the frame and the painted model rendered into its
  // view before the frame was painted; NaN where nothing was painted yet).
  std::vector<int> frames_painted;
  std::map<std::string, std::vector<float>> stage_ms;
  std::vector<float> misalignment;
  // Per painted frame, when the refine stage runs: the inliers' RMS residual before and
  // after the correction, texels (NaN where nothing was matched).
  std::vector<float> refine_before_px, refine_after_px;
  // Misalignment review images for the current frame (half size): the painted model
  // rendered into the frame's view, and the absolute difference as a heat map.
  cv::Mat rephoto_bgr, difference_heat;
  // Live sources (active for a live project): state, counts, offset, recording.
  LiveStatus live;
  // Per stream, the poses of its latest frames painted live (up to 2 * kLivePathFrames): the
  // paths the 3D view draws when the poses come from a feed (the geometry's are empty then).
  std::vector<std::vector<Rigid3d>> live_paths;
  // The first stream's live path that has poses (empty when none has).
  const std::vector<Rigid3d>& FirstLivePath() const {
    static const std::vector<Rigid3d> kNone;
    for (const std::vector<Rigid3d>& path : live_paths)
      if (!path.empty()) return path;
    return kNone;
  }
  static constexpr size_t kLivePathFrames = 1000;
};

struct RunnerOptions {
  bool debug_images = true;       // stage debug images for the frames that are shown
  bool misalignment = true;       // render the painted model into each frame's view
  int publish_interval_ms = 100;  // while playing, publish at most this often
  // The per-frame histories (stage_ms, misalignment, ...) keep the last history_frames to
  // 2 * history_frames painted frames: on an endless live stream neither the app's memory
  // nor the copy made at each publish grows without bound.
  int history_frames = 20000;
  // Live sources: the worker waits at most this long for a frame before it looks at its
  // commands again (and publishes the sources' state at least every publish_interval_ms).
  int live_poll_ms = 50;
  // Stepping back (a seek behind the frame shown): the painting state is saved every
  // snapshot_every frames (before the first frame too), and a seek back paints on from the
  // nearest saved state at or before its frame instead of from the first frame. The states
  // hold at most snapshot_budget_mb; past it they are thinned (every other one dropped), so
  // they stay spread over the capture. 0: none kept (a seek back reopens the project).
  int snapshot_every = 10;
  int snapshot_budget_mb = 1024;
  // Tests: called on the worker thread with every snapshot it publishes, in order.
  std::function<void(const RunnerSnapshot&)> on_publish;
};

class PipelineRunner {
 public:
  explicit PipelineRunner(const RunnerOptions& options = RunnerOptions());
  ~PipelineRunner();

  // (Re)opens the project with these settings and starts from frame 0, paused.
  void Restart(const Project& project);
  void Play();
  void Pause();          // also stops a seek under way at the last frame it painted
  void Step();           // paints the next frame, then pauses
  void Seek(int frame);  // paints up to `frame` (restarting when it lies behind), pauses
  // Live projects: records the frames painted from now on (with their poses) to `dir` as
  // a project to replay (SessionRecorder); "" stops and writes DIR/project.json. A
  // recording also stops when the live video ends or the project restarts.
  void Record(const std::string& dir);
  // Blocks until the queue is empty and the worker is idle (tests, --screenshot).
  void WaitIdle();
  std::shared_ptr<const RunnerSnapshot> Snapshot() const;

 private:
  struct Command {
    enum Kind { kRestart, kPlay, kPause, kStep, kSeek, kRecord, kQuit } kind;
    Project project;
    int frame = 0;
    std::string path;
  };
  enum class Painted { kFrame, kWaiting, kEnded };
  struct Session;
  void Post(Command command);
  void Loop();   // Serve(), and after an exception the error as the status
  void Serve();  // commands and painting until kQuit
  // One command (Serve, between frames); false for kQuit.
  bool Handle(Command command, std::chrono::steady_clock::time_point* last_publish);
  // kWaiting: a live source has no frame yet; kEnded: the end of the video, or an error.
  Painted PaintNext(bool show);
  void OpenSession(const Project& project);
  // A seek back to `frame` from the nearest saved state; false when none (reopen instead).
  bool SeekBackFromSnapshot(int frame);
  void SetRecording(const std::string& dir);
  void Publish(bool with_painted);

  RunnerOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::deque<Command> queue_;
  bool busy_ = false;
  std::shared_ptr<const RunnerSnapshot> snapshot_;
  // Worker-only state.
  std::unique_ptr<Session> session_;
  RunnerSnapshot working_;
  bool playing_ = false;
  int seek_target_ = -1;
  // The last project opened (its file) and how long its steps took: the estimate of the
  // steps without a progress of their own when it opens again.
  std::string last_open_file_;
  PaintJob::OpenSeconds last_open_;
  std::thread thread_;
};

}  // namespace fresco
