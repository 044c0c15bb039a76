// Timestamped camera poses from a tracker, and the pose at any time between two of them:
// the camera centre interpolated linearly, its orientation by SLERP (constant angular
// velocity between the two samples). Times are seconds on the tracker's clock.
//
// A video frame taken at `t_video` (seconds on the video's clock, its first frame at 0) is
// seen from the pose at `t_video + time_offset_s` on the tracker's clock (the project's
// `time_offset_s`: tracker clock minus video clock).
#pragma once

#include <cstddef>
#include <deque>

#include "pipeline/core/rigid3.h"

namespace fresco {

struct TimedPose {
  double timestamp_s = 0.0;  // tracker clock
  Rigid3d world_from_cam;    // TUM's convention: the camera's position and orientation
};

// The pose between `a` and `b` at `t` (a.timestamp_s <= t <= b.timestamp_s; outside, the
// nearer sample's motion is extrapolated linearly). Returns cam_from_world.
Rigid3d InterpolatePose(const TimedPose& a, const TimedPose& b, double t);

struct PoseTrackOptions {
  // Samples further apart than this are a gap: no pose is interpolated across it.
  double max_gap_s = 0.5;
  // A time this far beyond the first or last sample still gets the end sample's pose
  // extrapolated (0: only times inside the track).
  double max_extrapolate_s = 0.0;
  // Oldest samples are forgotten beyond this many (memory stays bounded on a live feed).
  size_t max_samples = 100000;
};

// Poses in time order (samples may arrive out of order: each is inserted in place; a sample
// at a time already held replaces it).
class PoseTrack {
 public:
  explicit PoseTrack(PoseTrackOptions options = PoseTrackOptions()) : options_(options) {}

  void Add(const TimedPose& pose);
  // The cam_from_world pose at tracker time `t`; false when `t` is outside the track (beyond
  // max_extrapolate_s) or inside a gap.
  bool At(double t, Rigid3d* cam_from_world) const;

  size_t size() const { return samples_.size(); }
  bool empty() const { return samples_.empty(); }
  double first_time_s() const { return samples_.front().timestamp_s; }
  double last_time_s() const { return samples_.back().timestamp_s; }
  const std::deque<TimedPose>& samples() const { return samples_; }

 private:
  PoseTrackOptions options_;
  std::deque<TimedPose> samples_;
};

}  // namespace fresco
