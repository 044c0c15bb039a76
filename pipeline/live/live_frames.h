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
#pragma once

#include <deque>
#include <functional>
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
// Estimates the offset on the window's frames (see MakeTimeOffsetEstimator).
using OffsetEstimator =
    std::function<TimeOffsetEstimate(const std::vector<Frame>& window, const PoseAtTime& pose_at)>;
// Opens the video again after a stall (live streams).
using VideoOpener = std::function<Status(std::unique_ptr<VideoSource>* video)>;

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

 private:
  void CaptureLoop();
  bool Pull(Frame* frame, Status* status);  // the next frame from the queue or the file
  bool FillWindowAndEstimate(Status* status);
  bool Usable(const Frame& frame) const;
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
};

// The estimator for LiveFrames: paints the window into its own session (EstimationPipeline)
// over `scene` seen through `camera`, candidates around `centre_s`.
OffsetEstimator MakeTimeOffsetEstimator(const Scene* scene, const Camera& camera,
                                        const PipelineOptions& pipeline,
                                        const GroupingOptions& grouping, double texel_size_m,
                                        const TimeOffsetOptions& options);

}  // namespace fresco
