#include "pipeline/live/session_recorder.h"

#include <cstdio>
#include <filesystem>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/image_io.h"

namespace fresco {

Status SessionRecorder::Start(const std::string& dir, const Project& live_project) {
  dir_ = dir;
  project_ = live_project;
  poses_.clear();
  FRESCO_RETURN_IF_ERROR(MakeDirectories(dir));
  return frames_.Open(dir + "/frames");
}

Status SessionRecorder::Add(const Frame& frame, const Rigid3d& cam_from_world) {
  char name[32];
  std::snprintf(name, sizeof name, "%06d.png", static_cast<int>(poses_.size()));
  FRESCO_RETURN_IF_ERROR(WriteImage(frames_.path() + "/" + name, frame.bgr));
  PosedImage pose;
  pose.image_id = static_cast<int>(poses_.size());
  pose.name = name;
  pose.timestamp_s = frame.timestamp_s;
  pose.cam_from_world = cam_from_world;
  poses_.push_back(pose);
  return Status::Ok();
}

Status SessionRecorder::Finish(const std::vector<TimedPose>& tracker_poses) {
  // From here on DIR is rewritten: without project.json it is an incomplete recording, never
  // an earlier one's project with this one's poses.
  std::error_code ec;
  std::filesystem::remove(dir_ + "/project.json", ec);
  FRESCO_RETURN_IF_ERROR(WriteTumTrajectory(dir_ + "/poses.txt", poses_));
  std::vector<PosedImage> tracker;
  for (const TimedPose& p : tracker_poses) {
    PosedImage pose;
    pose.timestamp_s = p.timestamp_s;
    pose.cam_from_world = p.world_from_cam.Inverse();
    tracker.push_back(pose);
  }
  FRESCO_RETURN_IF_ERROR(WriteTumTrajectory(dir_ + "/tracker_poses.txt", tracker));
  FRESCO_RETURN_IF_ERROR(frames_.Commit());
  Project replay = project_;
  // Paths resolve against the new folder: absolute for the inputs kept where they are.
  replay.scene = project_.Resolve(project_.scene);
  replay.camera = project_.Resolve(project_.camera);
  replay.truth.poses = project_.truth.poses.empty() ? "" : project_.Resolve(project_.truth.poses);
  replay.file_path.clear();
  replay.video = "frames/";
  replay.poses = "poses.txt";
  replay.time_offset_s = 0.0;
  replay.live.estimate_offset = false;
  return SaveProject(replay, dir_ + "/project.json");
}

}  // namespace fresco
