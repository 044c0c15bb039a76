#include "ui/core/live_session.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>

namespace fresco {
namespace {

double NowS() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

Status LiveSession::Open(const Project& project, const Capture& capture, const PaintSession& paint,
                         std::unique_ptr<LiveSession>* session) {
  std::unique_ptr<LiveSession> s(new LiveSession(project));
  // The tracker's poses for a recording come from the feed's bounded track (PosesBetween),
  // not from keeping every pose of an endless stream.
  FRESCO_RETURN_IF_ERROR(OpenLiveInputs(project, capture, paint, false, &s->inputs_));
  LiveSession* raw = s.get();
  s->feeder_ = std::thread([raw] { raw->Feed(); });
  *session = std::move(s);
  return Status::Ok();
}

LiveSession::~LiveSession() {
  if (recorder_) {
    std::string unused;
    StopRecording(&unused);
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  if (!feeder_.joinable()) return;  // opening failed
  inputs_.frames->Stop();           // a feeder waiting in LiveFrames::Next returns
  feeder_.join();
}

void LiveSession::Feed() {
  for (;;) {
    PosedFrame frame;
    Status status;
    const bool got = inputs_.frames->Next(&frame, &status);
    // A malformed pose line stops the feed: the session ends with its error (as `fresco run`).
    const Status feed_error = inputs_.feed ? inputs_.feed->error() : Status::Ok();
    std::unique_lock<std::mutex> lock(mutex_);
    if (!got || !feed_error.ok()) {
      ended_ = true;
      end_status_ = feed_error.ok() ? status : feed_error;
      changed_.notify_all();
      return;
    }
    changed_.wait(lock, [this] { return !slot_ || stop_; });
    if (stop_) return;
    slot_ = std::move(frame);
    changed_.notify_all();
  }
}

LiveSession::Poll LiveSession::Next(int timeout_ms, PosedFrame* frame, std::string* end) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait_for(lock, std::chrono::milliseconds(timeout_ms),
                    [this] { return slot_.has_value() || ended_; });
  if (slot_) {  // frames already taken from the source are painted before its end
    *frame = std::move(*slot_);
    slot_.reset();
    changed_.notify_all();
    delivered_any_ = true;
    last_pose_time_s_ = frame->pose_time_s;
    return Poll::kFrame;
  }
  if (!ended_) return Poll::kWaiting;
  *end = end_status_.ok() ? "live video ended: " + inputs_.frames->stats().end_reason
                          : "error: " + end_status_.message();
  return Poll::kEnded;
}

Status LiveSession::StartRecording(const std::string& dir) {
  if (recorder_) return Status::Error("already recording to " + record_dir_);
  auto recorder = std::make_unique<SessionRecorder>();
  if (Status s = recorder->Start(dir, project_); !s.ok()) {
    record_error_ = s.message();
    return s;
  }
  recorder_ = std::move(recorder);
  record_dir_ = dir;
  record_error_.clear();
  recorded_frames_ = 0;
  record_from_s_ = std::numeric_limits<double>::infinity();
  record_to_s_ = -std::numeric_limits<double>::infinity();
  return Status::Ok();
}

void LiveSession::Record(const PosedFrame& frame) {
  if (!recorder_ || !frame.has_pose) return;
  if (Status s = recorder_->Add(frame.frame, frame.cam_from_world); !s.ok()) {
    record_error_ = s.message();  // the frames written so far stay, without a project
    recorder_.reset();
    return;
  }
  ++recorded_frames_;
  record_from_s_ = std::min(record_from_s_, frame.pose_time_s);
  record_to_s_ = std::max(record_to_s_, frame.pose_time_s);
}

Status LiveSession::StopRecording(std::string* project_path) {
  if (!recorder_) return Status::Error("not recording");
  // The tracker's own samples around what was recorded (tracker_poses.txt).
  const double margin = project_.live.max_pose_gap_s;
  std::vector<TimedPose> tracker;
  if (inputs_.feed) {
    tracker = inputs_.feed->PosesBetween(record_from_s_ - margin, record_to_s_ + margin);
  } else {
    for (const TimedPose& p : inputs_.track->samples())
      if (p.timestamp_s >= record_from_s_ - margin && p.timestamp_s <= record_to_s_ + margin)
        tracker.push_back(p);
  }
  const Status s = recorder_->Finish(tracker);
  recorder_.reset();
  if (!s.ok()) {
    record_error_ = s.message();
    return s;
  }
  recorded_project_ = record_dir_ + "/project.json";
  *project_path = recorded_project_;
  return Status::Ok();
}

LiveStatus LiveSession::CurrentStatus() {
  LiveStatus st;
  st.active = true;
  st.video = project_.Resolve(project_.video);
  st.poses = project_.Resolve(project_.poses);
  const LiveFramesStats f = inputs_.frames->stats();
  st.frames_received = f.frames_received;
  st.frames_dropped = f.frames_dropped + f.frames_held_dropped;
  st.frames_delivered = f.frames_delivered;
  st.frames_without_pose = f.frames_without_pose;
  st.queue_capacity = f.queue_capacity;
  st.queue_high_water = f.queue_high_water;
  st.video_reopens = f.video_reopens;
  st.video_clock = f.video_clock;
  st.end_reason = f.end_reason;
  st.time_offset_s = f.time_offset_s;
  st.offset_estimated = f.offset_estimated;
  st.offset_estimating =
      project_.live.estimate_offset && f.estimate.candidates.empty() && f.estimate.note.empty();
  st.offset_score = f.estimate.score;
  st.offset_note = f.estimate.note;
  st.offset_track_points = static_cast<int>(f.offset_track.size());
  if (!f.offset_track.empty()) {
    st.offset_track_last_s = f.offset_track.back().offset_s;
    st.offset_track_last_applied = f.offset_track.back().applied;
  }
  const double now = NowS();
  if (f.frames_received != last_received_) {
    last_received_ = f.frames_received;
    last_frame_wall_s_ = now;
  }
  st.seconds_since_frame = last_frame_wall_s_ < 0 ? -1 : now - last_frame_wall_s_;
  if (inputs_.feed) {
    const PoseFeedStats p = inputs_.feed->stats();
    st.pose_feed = true;
    st.poses_connected = p.connected;
    st.poses_received = p.poses;
    st.pose_reconnects = p.reconnects;
    st.pose_gap_known = !p.gaps.empty();
    if (st.pose_gap_known) {
      st.pose_gap_tracker_s = p.gaps.back().tracker_gap_s();
      st.pose_gap_disconnected_s = p.gaps.back().disconnected_s;
    }
    st.seconds_since_pose = p.seconds_since_last_pose;
    st.pose_lag_known = delivered_any_ && p.poses > 0;
    if (st.pose_lag_known) st.pose_lag_s = p.latest_time_s - last_pose_time_s_;
  }

  bool ended = false;
  Status end;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ended = ended_;
    end = end_status_;
  }
  std::vector<std::string> problems;
  char line[200];
  if (ended) {
    st.state = end.ok() ? "ended" : "error";
    problems.push_back(end.ok() ? "live video ended: " + f.end_reason : "error: " + end.message());
  } else if (f.frames_received == 0) {
    st.state = "waiting for frames";
  } else if (st.seconds_since_frame > kStalledAfterS) {
    st.state = "stalled";
    std::snprintf(line, sizeof line, "video stalled: no frame for %.1f s", st.seconds_since_frame);
    problems.push_back(std::string(line) + " (" + st.video + ")");
  } else {
    st.state = "receiving";
  }
  if (st.pose_feed && !ended) {
    if (!st.poses_connected) {
      problems.push_back("pose feed disconnected, reconnecting (" + st.poses + ")");
    } else if (st.seconds_since_pose > kStalledAfterS) {
      std::snprintf(line, sizeof line, "pose feed stalled: no pose for %.1f s",
                    st.seconds_since_pose);
      problems.push_back(std::string(line) + " (" + st.poses + ")");
    }
  }
  for (const std::string& p : problems) {
    if (!st.problem.empty()) st.problem += "; ";
    st.problem += p;
  }

  st.recording = recorder_ != nullptr;
  st.record_dir = record_dir_;
  st.recorded_frames = recorded_frames_;
  st.recorded_project = recorded_project_;
  st.record_error = record_error_;
  return st;
}

}  // namespace fresco
