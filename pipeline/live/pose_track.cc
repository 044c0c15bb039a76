#include "pipeline/live/pose_track.h"

#include <algorithm>
#include <cmath>

namespace fresco {

Rigid3d InterpolatePose(const TimedPose& a, const TimedPose& b, double t) {
  const double span = b.timestamp_s - a.timestamp_s;
  const double u = span > 0 ? (t - a.timestamp_s) / span : 0.0;
  // Eigen's slerp takes the shorter way round and, for u outside [0, 1], carries the same
  // angular velocity on (extrapolation).
  const Eigen::Quaterniond q = a.world_from_cam.rotation.normalized().slerp(
      u, b.world_from_cam.rotation.normalized());
  const Eigen::Vector3d centre = a.world_from_cam.translation +
                                 u * (b.world_from_cam.translation - a.world_from_cam.translation);
  return Rigid3d(q.normalized(), centre).Inverse();
}

void PoseTrack::Add(const TimedPose& pose) {
  const auto later =
      std::lower_bound(samples_.begin(), samples_.end(), pose.timestamp_s,
                       [](const TimedPose& s, double t) { return s.timestamp_s < t; });
  if (later != samples_.end() && later->timestamp_s == pose.timestamp_s) {
    *later = pose;
  } else {
    samples_.insert(later, pose);
  }
  while (samples_.size() > options_.max_samples) samples_.pop_front();
}

bool PoseTrack::At(double t, Rigid3d* cam_from_world) const {
  if (samples_.empty()) return false;
  if (samples_.size() == 1) {
    if (std::abs(t - samples_.front().timestamp_s) > options_.max_extrapolate_s) return false;
    *cam_from_world = samples_.front().world_from_cam.Inverse();
    return true;
  }
  if (t < first_time_s() - options_.max_extrapolate_s) return false;
  if (t > last_time_s() + options_.max_extrapolate_s) return false;
  auto later = std::lower_bound(samples_.begin(), samples_.end(), t,
                                [](const TimedPose& s, double x) { return s.timestamp_s < x; });
  if (later != samples_.end() && later->timestamp_s == t) {  // a sample's own time (even
    *cam_from_world = later->world_from_cam.Inverse();       // next to a gap)
    return true;
  }
  if (later == samples_.begin()) ++later;  // before the first: extrapolate back
  if (later == samples_.end()) --later;    // after the last: extrapolate on
  const TimedPose& b = *later;
  const TimedPose& a = *(later - 1);
  if (b.timestamp_s - a.timestamp_s > options_.max_gap_s) return false;
  *cam_from_world = InterpolatePose(a, b, t);
  return true;
}

}  // namespace fresco
