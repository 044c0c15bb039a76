#include "pipeline/live/live_input.h"

namespace fresco {
namespace {

VideoSourceOptions VideoOptions(const LiveOptions& live) {
  VideoSourceOptions options;
  options.open_timeout_s = live.open_timeout_s;
  options.read_timeout_s = live.read_timeout_s;
  options.stream_clock = live.stream_clock;
  return options;
}

}  // namespace

bool IsLiveProject(const Project& project) {
  for (const StreamSpec& stream : project.Streams())
    if (IsUrlOrDevice(stream.video) || IsUrlOrDevice(stream.poses)) return true;
  return false;
}

Status OpenLiveInputs(const Project& project, const Capture& capture, OffsetEstimator estimator,
                      bool keep_tracker_poses, LiveInputs* inputs) {
  if (capture.cameras.size() != 1) {
    return Status::Error(project.camera + ": a live capture needs exactly one camera, got " +
                         std::to_string(capture.cameras.size()));
  }
  inputs->camera = &capture.cameras.begin()->second;
  PoseTrackOptions track_options;
  track_options.max_gap_s = project.live.max_pose_gap_s;
  track_options.max_extrapolate_s = project.live.max_pose_extrapolate_s;
  WaitPoseAtTime pose_at;
  if (IsUrlOrDevice(project.poses)) {
    PoseFeedOptions feed_options;
    feed_options.connect_timeout_s = project.live.connect_timeout_s;
    feed_options.reconnect_give_up_s = project.live.pose_reconnect_give_up_s;
    feed_options.track = track_options;
    feed_options.keep_all = keep_tracker_poses;
    FRESCO_RETURN_IF_ERROR(PoseFeed::Open(project.poses, feed_options, &inputs->feed));
    PoseFeed* feed = inputs->feed.get();
    pose_at = [feed](double t, double timeout_s, Rigid3d* pose) {
      return feed->WaitPoseAt(t, timeout_s, pose);
    };
  } else {
    if (!capture.poses_are_tum) {
      return Status::Error(project.Resolve(project.poses) +
                           ": a live video is matched to poses by time: give TUM poses "
                           "(timestamps) or a pose feed (tcp://, udp://, fifo://)");
    }
    inputs->track = std::make_shared<PoseTrack>(track_options);
    for (const PosedImage& p : capture.poses)
      inputs->track->Add(TimedPose{p.timestamp_s, p.cam_from_world.Inverse()});
    std::shared_ptr<PoseTrack> track = inputs->track;
    pose_at = [track](double t, double, Rigid3d* pose) { return track->At(t, pose); };
  }

  const std::string video_path = project.Resolve(project.video);
  const VideoSourceOptions video_options = VideoOptions(project.live);
  std::unique_ptr<VideoSource> video;
  FRESCO_RETURN_IF_ERROR(OpenVideoSource(video_path, video_options, &video));
  VideoOpener reopen = [video_path, video_options](std::unique_ptr<VideoSource>* again) {
    return OpenVideoSource(video_path, video_options, again);
  };
  if (!project.live.estimate_offset && !project.live.track_offset) estimator = nullptr;
  inputs->frames =
      std::make_unique<LiveFrames>(std::move(video), std::move(reopen), std::move(pose_at),
                                   project.live, project.time_offset_s, std::move(estimator));
  return Status::Ok();
}

}  // namespace fresco
