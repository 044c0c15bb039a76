#include "pipeline/run/live_status.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>

namespace fresco {
namespace {

double NowS() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string Seconds(const char* what, double s) {
  char line[160];
  std::snprintf(line, sizeof line, "%s for %.1f s", what, s);
  return line;
}

// "connecting" aside (before the inputs exist), the state from what the run and the frames
// say, and the problems worth a line in the status bar.
void Judge(const LiveStatus& s, bool ended, const Status& end, std::string* state,
           std::vector<std::string>* problems) {
  if (ended) {
    *state = end.ok() ? "ended" : "error";
    problems->push_back(end.ok() ? "live video ended: " + s.frames.end_reason
                                 : "error: " + end.message());
  } else if (s.frames.frames_received == 0) {
    *state = "waiting for frames";
  } else if (s.seconds_since_frame > LiveWatch::kStalledAfterS) {
    *state = "stalled";
    problems->push_back(Seconds("video stalled: no frame", s.seconds_since_frame) + " (" +
                        s.video + ")");
  } else {
    *state = "receiving";
  }
  if (!s.pose_feed || ended) return;
  if (!s.feed.connected)
    problems->push_back("pose feed disconnected, reconnecting (" + s.poses + ")");
  else if (s.feed.seconds_since_last_pose > LiveWatch::kStalledAfterS)
    problems->push_back(Seconds("pose feed stalled: no pose", s.feed.seconds_since_last_pose) +
                        " (" + s.poses + ")");
}

}  // namespace

LiveStatus LiveWatch::Read(const Project& stream, const LiveInputs& inputs, bool ended,
                           const Status& end, double last_pose_time_s) {
  LiveStatus s;
  s.active = true;
  s.video = stream.Resolve(stream.video);
  s.poses = stream.Resolve(stream.poses);
  s.frames = inputs.frames->stats();
  s.offset_estimating = stream.live.estimate_offset && s.frames.estimate.candidates.empty() &&
                        s.frames.estimate.note.empty();
  const double now = NowS();
  if (s.frames.frames_received != last_received_) {
    last_received_ = s.frames.frames_received;
    last_frame_wall_s_ = now;
  }
  s.seconds_since_frame = last_frame_wall_s_ < 0 ? -1 : now - last_frame_wall_s_;
  if (inputs.feed) {
    s.pose_feed = true;
    s.pose_feed_address = inputs.feed->address();
    s.feed = inputs.feed->stats();
    s.pose_lag_known = last_pose_time_s >= 0 && s.feed.poses > 0;
    if (s.pose_lag_known) s.pose_lag_s = s.feed.latest_time_s - last_pose_time_s;
  }
  std::vector<std::string> problems;
  Judge(s, ended, end, &s.state, &problems);
  for (const std::string& p : problems) {
    if (!s.problem.empty()) s.problem += "; ";
    s.problem += p;
  }
  return s;
}

Status LiveRecording::Start(const std::string& dir, const Project& stream, bool whole_track) {
  if (recorder_) return Status::Error("already recording to " + dir_);
  auto recorder = std::make_unique<SessionRecorder>();
  if (Status s = recorder->Start(dir, stream); !s.ok()) {
    error_ = s.message();
    return s;
  }
  recorder_ = std::move(recorder);
  project_ = stream;
  whole_track_ = whole_track;
  dir_ = dir;
  error_.clear();
  frames_ = 0;
  from_s_ = std::numeric_limits<double>::infinity();
  to_s_ = -std::numeric_limits<double>::infinity();
  return Status::Ok();
}

Status LiveRecording::Add(const PosedFrame& frame) {
  if (!recorder_ || !frame.has_pose) return Status::Ok();
  if (Status s = recorder_->Add(frame.frame, frame.cam_from_world); !s.ok()) {
    error_ = s.message();
    recorder_.reset();
    return s;
  }
  ++frames_;
  from_s_ = std::min(from_s_, frame.pose_time_s);
  to_s_ = std::max(to_s_, frame.pose_time_s);
  return Status::Ok();
}

Status LiveRecording::Finish(const LiveInputs& inputs, std::string* project_path) {
  if (!recorder_) return Status::Error("not recording");
  // The tracker's own samples around what was recorded (tracker_poses.txt).
  const double margin = project_.live.max_pose_gap_s;
  std::vector<TimedPose> tracker;
  if (inputs.feed && whole_track_) {
    tracker = inputs.feed->AllPoses();
  } else if (inputs.feed) {
    tracker = inputs.feed->PosesBetween(from_s_ - margin, to_s_ + margin);
  } else {
    for (const TimedPose& p : inputs.track->samples())
      if (whole_track_ || (p.timestamp_s >= from_s_ - margin && p.timestamp_s <= to_s_ + margin))
        tracker.push_back(p);
  }
  const Status s = recorder_->Finish(tracker);
  recorder_.reset();
  if (!s.ok()) {
    error_ = s.message();
    return s;
  }
  project_path_ = dir_ + "/project.json";
  *project_path = project_path_;
  return Status::Ok();
}

void LiveRecording::Describe(LiveStatus* status) const {
  status->recording = recorder_ != nullptr;
  status->record_dir = dir_;
  status->recorded_frames = frames_;
  status->recorded_project = project_path_;
  status->record_error = error_;
}

}  // namespace fresco
