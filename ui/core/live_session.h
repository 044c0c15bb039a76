// The app's side of a live capture (issue 12): the same live core as `fresco run`
// (OpenLiveInputs: pose feed, video stream, LiveFrames with its bounded queue and offset
// estimation), read on a feeder thread so that the painting worker never blocks on a
// source: it polls for the next frame with a short timeout, stays responsive to commands
// and publishes the sources' state (connected, stalled, ended) while nothing arrives. Also
// records the session (SessionRecorder) while the Record toggle is on.
//
//   LiveFrames::Next (blocks) --(feeder thread)--> one-frame slot --> Poll (bounded wait)
//
// The slot holds one frame; the feeder waits for it to be taken, so frames the painter
// cannot take pile up in LiveFrames' queue, where they are dropped (newest wins) and
// counted, exactly as in `fresco run`.
#pragma once

#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "pipeline/core/project.h"
#include "pipeline/live/live_input.h"
#include "pipeline/live/session_recorder.h"

namespace fresco {

// What the Pipeline panel and the status bar show about live sources (RunnerSnapshot::live).
struct LiveStatus {
  bool active = false;       // the project's sources are live
  // Streams in the project (Project::Streams()); with several, the figures below are the
  // first live stream's and recording is not offered.
  int streams = 1;
  std::string video, poses;  // the addresses (or files) as resolved
  // "connecting", "waiting for frames", "receiving", "stalled", "ended", "error".
  std::string state;
  // Something is wrong (a source stalled, disconnected, ended or failed): one line for the
  // status bar; "" when all is well.
  std::string problem;
  long long frames_received = 0, frames_dropped = 0, frames_delivered = 0;
  long long frames_without_pose = 0;
  long long frames_painted = 0;  // of this stream, by the app (set by PipelineRunner)
  int queue_capacity = 0, queue_high_water = 0, video_reopens = 0;
  double seconds_since_frame = -1;  // wall time since the last frame arrived (-1: none yet)
  std::string video_clock;
  bool pose_feed = false;  // poses from a feed (else a TUM file)
  bool poses_connected = false;
  long long poses_received = 0, pose_reconnects = 0;
  // The last disconnection of the pose feed: tracker time it spans (NaN until the first
  // pose after it) and wall seconds without a connection; valid when pose_gap_known.
  bool pose_gap_known = false;
  double pose_gap_tracker_s = 0, pose_gap_disconnected_s = 0;
  double seconds_since_pose = -1;
  // Pose-match lag: the newest tracker sample's time minus the pose time of the last frame
  // delivered (frame time + offset), seconds; > 0: the tracker is ahead of the video.
  // Known once both exist, with poses from a feed.
  double pose_lag_s = 0;
  bool pose_lag_known = false;
  double time_offset_s = 0;
  bool offset_estimating = false;  // estimation on, not finished yet
  bool offset_estimated = false;
  double offset_score = 0;  // mean |grey difference| at the estimate
  std::string offset_note;
  // Offset tracking (live.track_offset): re-estimations so far, and the last one's estimate
  // and whether it replaced the offset in use.
  int offset_track_points = 0;
  double offset_track_last_s = 0;
  bool offset_track_last_applied = false;
  std::string end_reason;
  // Recording (the Record toggle).
  bool recording = false;
  std::string record_dir;
  int recorded_frames = 0;       // by the current (or last) recording
  std::string recorded_project;  // project.json of the last finished recording
  std::string record_error;
};

class LiveSession {
 public:
  // Stalled: no frame received for this long (while the source has not ended).
  static constexpr double kStalledAfterS = 1.0;

  // Opens the project's live inputs (blocks up to the connect and open timeouts); `capture`
  // (loaded without the video) and `paint` must outlive the session.
  static Status Open(const Project& project, const Capture& capture, const PaintSession& paint,
                     std::unique_ptr<LiveSession>* session);
  ~LiveSession();
  LiveSession(const LiveSession&) = delete;
  LiveSession& operator=(const LiveSession&) = delete;

  enum class Poll { kFrame, kWaiting, kEnded };
  // The next frame within `timeout_ms`; kEnded when the video ended or a source failed
  // (`end` then says why: "live video ended: ...", "error: ...").
  Poll Next(int timeout_ms, PosedFrame* frame, std::string* end);
  const Camera& camera() const { return *inputs_.camera; }

  // Recording: frames painted from now on go to DIR (SessionRecorder); Stop writes the
  // project and returns its path. Errors name the folder or file.
  Status StartRecording(const std::string& dir);
  Status StopRecording(std::string* project_path);
  // Records a frame about to be painted (when recording); an error stops the recording.
  void Record(const PosedFrame& frame);
  bool recording() const { return recorder_ != nullptr; }

  LiveStatus CurrentStatus();

 private:
  explicit LiveSession(Project project) : project_(std::move(project)) {}
  void Feed();

  Project project_;
  LiveInputs inputs_;
  std::thread feeder_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<PosedFrame> slot_;
  bool ended_ = false, stop_ = false;
  Status end_status_;
  // Worker-only.
  long long last_received_ = 0;
  double last_frame_wall_s_ = -1;
  double last_pose_time_s_ = 0;
  bool delivered_any_ = false;
  std::unique_ptr<SessionRecorder> recorder_;
  std::string record_dir_, recorded_project_, record_error_;
  int recorded_frames_ = 0;
  double record_from_s_ = 0, record_to_s_ = 0;  // tracker times covered by the recording
};

}  // namespace fresco
