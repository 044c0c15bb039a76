// One live stream's state as every client reports it: `fresco run` writes it into
// metrics.json, the app's Pipeline panel and status bar show it. LiveWatch reads it from the
// stream's live inputs (opened by OpenPaintJob); LiveRecording writes the frames a run paints,
// with the tracker's poses around them, as a project to replay (SessionRecorder).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/project.h"
#include "pipeline/core/status.h"
#include "pipeline/live/live_input.h"
#include "pipeline/live/session_recorder.h"

namespace fresco {

struct LiveStatus {
  bool active = false;  // the project's sources are live
  // Streams in the project (Project::Streams()); with several, the figures below are the
  // first live stream's and recording is not offered.
  int streams = 1;
  std::string video, poses;  // the addresses (or files) as resolved
  // "connecting", "waiting for frames", "receiving", "stalled", "ended", "error".
  std::string state;
  // Something is wrong (a source stalled, disconnected, ended or failed): one line for the
  // status bar; "" when all is well.
  std::string problem;
  // The frames' side as LiveFrames counts it: received, dropped, delivered, the queue, the
  // time offset in use, its estimate and its tracking (every candidate and re-estimation).
  LiveFramesStats frames;
  long long frames_painted = 0;  // of this stream, by the run
  double seconds_since_frame = -1;  // wall time since the last frame arrived (-1: none yet)
  bool offset_estimating = false;   // estimation on, not finished yet
  // Poses from a feed (else a TUM file): its address and counts, gaps, connection.
  bool pose_feed = false;
  std::string pose_feed_address;
  PoseFeedStats feed;
  // Pose-match lag: the newest tracker sample's time minus the pose time of the last frame
  // delivered (frame time + offset), seconds; > 0: the tracker is ahead of the video.
  // Known once both exist, with poses from a feed.
  double pose_lag_s = 0;
  bool pose_lag_known = false;
  // Recording (the app's Record toggle, `fresco run --record`).
  bool recording = false;
  std::string record_dir;
  int recorded_frames = 0;       // by the current (or last) recording
  std::string recorded_project;  // project.json of the last finished recording
  std::string record_error;

  // The last disconnection of the pose feed, when there was one.
  const PoseFeedGap* last_gap() const { return feed.gaps.empty() ? nullptr : &feed.gaps.back(); }
};

// Reads one live stream's state; keeps what the reading needs from one call to the next
// (when a frame last arrived).
class LiveWatch {
 public:
  // Stalled: no frame received for this long (while the source has not ended).
  static constexpr double kStalledAfterS = 1.0;

  // `stream`: the stream's own project (Project::ForStream); `ended`: the run ended, with
  // `end` its error (ok: the video ended); `last_pose_time_s`: pose time of the last frame
  // the run took from this stream (< 0: none yet).
  LiveStatus Read(const Project& stream, const LiveInputs& inputs, bool ended, const Status& end,
                  double last_pose_time_s);

 private:
  long long last_received_ = 0;
  double last_frame_wall_s_ = -1;
};

// The frames a run paints from a live stream, written as a project to replay.
class LiveRecording {
 public:
  // Frames added from now on go to `dir`; errors name the folder or file. `whole_track`:
  // tracker_poses.txt gets every pose the feed received (opened with keep_tracker_poses:
  // `fresco run --record` records the whole run), else the samples the feed's bounded track
  // still holds around the recorded frames (the app records from any moment of an endless
  // stream).
  Status Start(const std::string& dir, const Project& stream, bool whole_track = false);
  // A frame about to be painted (with its pose); an error stops the recording (the frames
  // written so far stay, without a project).
  Status Add(const PosedFrame& frame);
  // Writes DIR/project.json with the tracker's own samples around what was recorded
  // (tracker_poses.txt) and returns its path.
  Status Finish(const LiveInputs& inputs, std::string* project_path);
  bool active() const { return recorder_ != nullptr; }
  // Into a LiveStatus: recording, its folder, frames, last project and error.
  void Describe(LiveStatus* status) const;

 private:
  std::unique_ptr<SessionRecorder> recorder_;
  Project project_;
  bool whole_track_ = false;
  std::string dir_, project_path_, error_;
  int frames_ = 0;
  double from_s_ = 0, to_s_ = 0;  // tracker times covered by the recording
};

}  // namespace fresco
