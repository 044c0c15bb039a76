// Frames with their poses from live sources, for the painting loop (`fresco run`, the app):
//
//   video source --(capture thread)--> LatestQueue (bounded, newest wins) --> Next()
//                                                                              |
//   pose feed / TUM file --> pose at (frame time + time offset), interpolated -+
//
// A live video (camera, stream) is read on its own thread into a bounded queue: when the
// painter is slower than the stream, the oldest waiting frames are dropped and counted, and
// memory stays bounded. A file video is read directly (nothing is dropped). When the video
// stops delivering (its end, or no frame within its read timeout) it is reopened up to
// `reconnects` times, then the stream has ended (end_reason tells which of the two). With offset
// estimation on, the first frames are held (at most twice the window) until the poses cover them
// for every candidate offset, then the offset is estimated on another thread while the frames
// arriving meanwhile are held too (at most four windows or queue_frames in all: beyond, the oldest
// are dropped and counted), and the held frames are handed out first.
//
// With offset tracking on (LiveOptions::track_offset), the offset is estimated again every
// offset_track_every_frames frames over the last window, around the offset in use, on
// another thread while painting goes on (with a file video, Next waits for it: replays are
// reproducible); the estimate replaces the offset in use only when its score is clearly
// lower (offset_track_min_gain) than the offset in use scores on the same frames. Each
// re-estimation is reported (LiveFramesStats::offset_track).
#pragma once

#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/core/project.h"
#include "pipeline/core/video_source.h"
#include "pipeline/live/latest_queue.h"
#include "pipeline/live/time_offset_estimation.h"

namespace fresco {

struct PosedFrame {
  Frame frame;
  bool has_pose = false;
  Rigid3d cam_from_world;
  double pose_time_s = 0.0;  // tracker time the pose was taken at (frame time + offset)
};

// The pose at tracker time `t`, waiting up to `timeout_s` for the tracker to get there.
using WaitPoseAtTime = std::function<bool(double t, double timeout_s, Rigid3d* cam_from_world)>;
// Estimates the offset on the window's frames, candidates within centre_s +- search_s (see
// pipeline/run/offset_estimator.h).
using OffsetEstimator = std::function<TimeOffsetEstimate(
    const std::vector<Frame>& window, const PoseAtTime& pose_at, double centre_s, double search_s)>;
// Opens the video again after a stall (live streams).
using VideoOpener = std::function<Status(std::unique_ptr<VideoSource>* video)>;

// One re-estimation of the offset while tracking it (LiveOptions::track_offset).
struct OffsetTrackPoint {
  double window_start_s = 0.0;  // video times of the window's first and last frames
  double time_s = 0.0;
  int frames = 0;         // frames in the window
  double offset_s = 0.0;  // the estimate (the offset in use when not ok)
  double score = 0.0;     // its score (mean |grey difference|, lower is better)
  // The score of the offset in use on the same frames (NaN when it could not be scored).
  double current_score = 0.0;
  bool ok = false;       // the estimation succeeded
  bool applied = false;  // the estimate replaced the offset in use
  double seconds = 0.0;  // wall time of the estimation
};

// LiveFramesStats::offset_track holds at most this many points (the oldest are forgotten).
constexpr size_t kMaxOffsetTrackPoints = 256;

struct LiveFramesStats {
  long long frames_received = 0;      // decoded from the source
  long long frames_dropped = 0;       // pushed out of the full queue (newest wins)
  long long frames_held_dropped = 0;  // pushed out of the estimation window's hold
  long long frames_delivered = 0;     // handed to the painter
  long long frames_without_pose = 0;
  int queue_capacity = 0;
  int queue_high_water = 0;  // most frames ever waiting at once
  int video_reopens = 0;
  std::string video_clock;     // "stream", "arrival" or "index"
  std::string end_reason;      // why the video ended
  double time_offset_s = 0.0;  // used for matching (the estimate when estimated)
  bool offset_estimated = false;
  TimeOffsetEstimate estimate;
  std::vector<OffsetTrackPoint> offset_track;  // re-estimations, in order (tracking on)
};

class LiveFrames {
 public:
  LiveFrames(std::unique_ptr<VideoSource> video, VideoOpener reopen, WaitPoseAtTime pose_at,
             const LiveOptions& options, double time_offset_s, OffsetEstimator estimator);
  ~LiveFrames();
  LiveFrames(const LiveFrames&) = delete;
  LiveFrames& operator=(const LiveFrames&) = delete;

  // The next frame (with its pose when the tracker has one). False at the end of the video;
  // `status` holds an error when reading failed (a frame that does not decode, ...).
  bool Next(PosedFrame* out, Status* status);
  // Stops the capture thread (Next returns false once the queue is empty).
  void Stop();
  LiveFramesStats stats() const;
  // The video is a camera or a stream (not a file or folder replayed).
  bool RealTime() const { return live_; }

 private:
  void CaptureLoop();
  bool Pull(Frame* frame, Status* status);  // the next frame from the queue or the file
  bool FillWindowAndEstimate(Status* status);
  bool Usable(const Frame& frame) const { return Usable(frame, options_.offset_search_s); }
  // The poses cover the frame for every candidate within +-search_s of the offset in use.
  bool Usable(const Frame& frame, double search_s) const;
  // Offset tracking: remembers `frame`, starts a re-estimation when due, takes in one that
  // finished (a file video waits for it: replays are reproducible).
  void TrackOffset(const Frame& frame);
  void FinishTracking();
  // Why the live video ended: "the stream ended after N frames" when the source said so,
  // "stalled: no frame within X s after N frames" when reading timed out.
  std::string EndReason(bool timed_out, bool signals_end, long long frames) const;

  std::unique_ptr<VideoSource> video_;
  VideoOpener reopen_;
  WaitPoseAtTime pose_at_;
  LiveOptions options_;
  OffsetEstimator estimator_;
  bool live_ = false;
  LatestQueue<Frame> queue_;
  std::thread capture_;
  std::atomic<bool> stop_{false};

  mutable std::mutex mutex_;  // guards stats_ and capture_status_
  LiveFramesStats stats_;
  Status capture_status_;

  std::deque<Frame> held_;  // estimation window's frames, handed out first
  bool estimation_done_ = false;

  // Offset tracking (painter's thread only).
  std::deque<Frame> recent_;         // the last window of frames handed out
  int since_tracked_ = 0;            // frames handed out since the last re-estimation started
  OffsetTrackPoint tracking_point_;  // the running one's window and centre
  std::future<TimeOffsetEstimate> tracking_;  // last: finishes before the members it uses
};

}  // namespace fresco
