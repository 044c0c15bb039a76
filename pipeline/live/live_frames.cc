#include "pipeline/live/live_frames.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>
#include <limits>

namespace fresco {
namespace {

// While the offset is estimated, a live source's frames are held up to this many windows
// (or the queue's capacity when larger).
constexpr size_t kHoldWindows = 4;

}  // namespace

std::string LiveFrames::EndReason(bool timed_out, bool signals_end, long long frames) const {
  char reason[200];
  if (!timed_out) {
    std::snprintf(reason, sizeof reason, "the stream ended after %lld frames", frames);
  } else {
    std::snprintf(reason, sizeof reason, "stalled: no frame within %.1f s after %lld frames%s",
                  options_.read_timeout_s, frames,
                  signals_end ? ""
                              : " (the protocol does not signal the end of a stream: it "
                                "ended or stalled)");
  }
  return reason;
}

LiveFrames::LiveFrames(std::unique_ptr<VideoSource> video, VideoOpener reopen,
                       WaitPoseAtTime pose_at, const LiveOptions& options, double time_offset_s,
                       OffsetEstimator estimator)
    : video_(std::move(video)),
      reopen_(std::move(reopen)),
      pose_at_(std::move(pose_at)),
      options_(options),
      estimator_(std::move(estimator)),
      live_(video_->IsLive()),
      queue_(static_cast<size_t>(options.queue_frames)) {
  stats_.queue_capacity = options.queue_frames;
  stats_.time_offset_s = time_offset_s;
  stats_.video_clock = video_->Clock();
  if (live_) capture_ = std::thread([this] { CaptureLoop(); });
}

LiveFrames::~LiveFrames() { Stop(); }

void LiveFrames::Stop() {
  stop_ = true;
  if (capture_.joinable()) capture_.join();
  queue_.Close();
}

void LiveFrames::CaptureLoop() {
  int index = 0;
  double time_base_s = 0.0;  // after a reopen, the clock continues from the last frame
  double last_time_s = 0.0;
  while (!stop_) {
    Frame frame;
    Status status;
    if (video_->Next(&frame, &status)) {
      frame.timestamp_s += time_base_s;
      last_time_s = frame.timestamp_s;
      frame.index = index;
      char name[32];
      std::snprintf(name, sizeof name, "%06d.png", index++);
      frame.name = name;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ++stats_.frames_received;
        stats_.video_clock = video_->Clock();  // known once frames arrive
      }
      queue_.Push(std::move(frame));
      continue;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (!status.ok()) {
      capture_status_ = status;
      stats_.end_reason = status.message();
      break;
    }
    const bool timed_out = video_->TimedOut();
    const bool signals_end = video_->SignalsEnd();
    if (stats_.video_reopens < options_.reconnects && reopen_ && !stop_) {
      ++stats_.video_reopens;
      std::unique_ptr<VideoSource> again;
      if (reopen_(&again).ok()) {
        video_ = std::move(again);
        time_base_s = last_time_s + 1.0 / video_->Fps();
      }
      continue;
    }
    stats_.end_reason = EndReason(timed_out, signals_end, stats_.frames_received);
    break;
  }
  queue_.Close();
}

bool LiveFrames::Pull(Frame* frame, Status* status) {
  if (live_) {
    if (queue_.Pop(frame)) return true;
    std::lock_guard<std::mutex> lock(mutex_);
    *status = capture_status_;
    return false;
  }
  if (!video_->Next(frame, status)) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stats_.end_reason.empty())
      stats_.end_reason = status->ok() ? "end of the video" : status->message();
    return false;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  ++stats_.frames_received;
  return true;
}

bool LiveFrames::Usable(const Frame& frame, double search_s) const {
  double offset;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    offset = stats_.time_offset_s;
  }
  const double t = frame.timestamp_s + offset;
  Rigid3d unused;
  return pose_at_(t - search_s, 0.0, &unused) && pose_at_(t + search_s, 0.0, &unused);
}

void LiveFrames::TrackOffset(const Frame& frame) {
  if (tracking_.valid() &&
      tracking_.wait_for(std::chrono::milliseconds(0)) == std::future_status::ready)
    FinishTracking();
  const size_t window = static_cast<size_t>(options_.offset_window_frames);
  recent_.push_back(frame);
  recent_.back().bgr = frame.bgr.clone();  // the painter may write into its copy
  while (recent_.size() > window) recent_.pop_front();
  ++since_tracked_;
  if (since_tracked_ < options_.offset_track_every_frames || tracking_.valid()) return;
  std::vector<Frame> usable;
  for (const Frame& f : recent_)
    if (Usable(f, options_.offset_track_search_s)) usable.push_back(f);
  if (usable.size() < std::max<size_t>(4, window / 2)) return;  // the poses lag: next frame
  since_tracked_ = 0;
  tracking_point_ = OffsetTrackPoint();
  tracking_point_.window_start_s = usable.front().timestamp_s;
  tracking_point_.time_s = usable.back().timestamp_s;
  tracking_point_.frames = static_cast<int>(usable.size());
  {
    std::lock_guard<std::mutex> lock(mutex_);
    tracking_point_.offset_s = stats_.time_offset_s;  // the centre, until the estimate
  }
  const PoseAtTime pose_at = [this](double t, Rigid3d* pose) { return pose_at_(t, 0.0, pose); };
  tracking_ = std::async(std::launch::async, [this, usable = std::move(usable), pose_at,
                                              centre = tracking_point_.offset_s] {
    return estimator_(usable, pose_at, centre, options_.offset_track_search_s);
  });
  if (!live_) FinishTracking();
}

void LiveFrames::FinishTracking() {
  const TimeOffsetEstimate e = tracking_.get();
  OffsetTrackPoint p = tracking_point_;
  const double centre_s = p.offset_s;
  p.current_score = std::numeric_limits<double>::quiet_NaN();
  for (const TimeOffsetCandidate& c : e.candidates)
    if (c.offset_s == centre_s) p.current_score = c.score;
  p.ok = e.ok;
  p.seconds = e.seconds;
  if (e.ok) {
    p.offset_s = e.offset_s;
    p.score = e.score;
  }
  p.applied = e.ok && std::isfinite(p.current_score) &&
              e.score < (1.0 - options_.offset_track_min_gain) * p.current_score;
  std::lock_guard<std::mutex> lock(mutex_);
  if (p.applied) stats_.time_offset_s = p.offset_s;
  stats_.offset_track.push_back(p);
  if (stats_.offset_track.size() > kMaxOffsetTrackPoints)
    stats_.offset_track.erase(stats_.offset_track.begin());
}

bool LiveFrames::FillWindowAndEstimate(Status* status) {
  const size_t window = static_cast<size_t>(options_.offset_window_frames);
  auto usable_count = [&] {
    size_t n = 0;
    for (const Frame& f : held_) n += Usable(f) ? 1 : 0;
    return n;
  };
  Frame frame;
  while (usable_count() < window && Pull(&frame, status)) {
    held_.push_back(std::move(frame));
    if (held_.size() > 2 * window) {
      held_.pop_front();
      std::lock_guard<std::mutex> lock(mutex_);
      ++stats_.frames_held_dropped;
    }
  }
  if (!status->ok()) return false;
  // The video ended first: give the tracker a moment to cover the last frames.
  if (!held_.empty()) {
    Rigid3d unused;
    pose_at_(held_.back().timestamp_s + stats_.time_offset_s + options_.offset_search_s,
             options_.pose_wait_s, &unused);
  }
  std::vector<Frame> usable;
  for (const Frame& f : held_)
    if (Usable(f)) usable.push_back(f);
  const PoseAtTime pose_at = [this](double t, Rigid3d* pose) { return pose_at_(t, 0.0, pose); };
  TimeOffsetEstimate estimate;
  if (estimator_ && usable.size() >= 4) {
    // Estimate on another thread; meanwhile a live source's frames keep being held (up to
    // kHoldWindows windows, oldest dropped and counted beyond) instead of overflowing the
    // queue.
    auto running = std::async(std::launch::async, [&] {
      return estimator_(usable, pose_at, stats_.time_offset_s, options_.offset_search_s);
    });
    while (live_ && running.wait_for(std::chrono::milliseconds(0)) != std::future_status::ready) {
      if (!queue_.Pop(&frame, std::chrono::milliseconds(5))) continue;
      held_.push_back(std::move(frame));
      if (held_.size() > std::max(kHoldWindows * window, queue_.capacity())) {
        held_.pop_front();
        std::lock_guard<std::mutex> lock(mutex_);
        ++stats_.frames_held_dropped;
      }
    }
    estimate = running.get();
  } else {
    estimate.offset_s = stats_.time_offset_s;
    estimate.frames = static_cast<int>(usable.size());
    estimate.note =
        "too few frames with poses to estimate the offset (" + std::to_string(usable.size()) + ")";
  }
  std::lock_guard<std::mutex> lock(mutex_);
  stats_.estimate = estimate;
  stats_.offset_estimated = estimate.ok;
  if (estimate.ok) stats_.time_offset_s = estimate.offset_s;
  return true;
}

bool LiveFrames::Next(PosedFrame* out, Status* status) {
  *status = Status::Ok();
  if (options_.estimate_offset && !estimation_done_) {
    estimation_done_ = true;
    if (!FillWindowAndEstimate(status)) return false;
  }
  Frame frame;
  if (!held_.empty()) {
    frame = std::move(held_.front());
    held_.pop_front();
  } else if (!Pull(&frame, status)) {
    if (tracking_.valid()) FinishTracking();  // the series reports every re-estimation
    return false;
  }
  if (options_.track_offset && estimator_) TrackOffset(frame);
  double offset;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    offset = stats_.time_offset_s;
  }
  out->pose_time_s = frame.timestamp_s + offset;
  out->has_pose = pose_at_(out->pose_time_s, options_.pose_wait_s, &out->cam_from_world);
  out->frame = std::move(frame);
  std::lock_guard<std::mutex> lock(mutex_);
  ++stats_.frames_delivered;
  if (!out->has_pose) ++stats_.frames_without_pose;
  return true;
}

LiveFramesStats LiveFrames::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  LiveFramesStats s = stats_;
  s.frames_dropped = queue_.dropped();
  s.queue_high_water = static_cast<int>(queue_.high_water());
  return s;
}

}  // namespace fresco
