// Records a live session as a normal project for replay: DIR/frames/%06d.png (each frame
// painted, i.e. delivered with a pose; dropped frames are not recorded), DIR/poses.txt (TUM:
// each frame's pose as matched, interpolated at its time, the frame's video time as the
// timestamp; TUM poses match frames in order), DIR/tracker_poses.txt (every pose the
// tracker sent, its own clock) and DIR/project.json (the live project's scene, camera and
// settings with video "frames/", poses "poses.txt", time_offset_s 0 and estimation off).
// `fresco run DIR/project.json` then replays what was painted live.
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/poses.h"
#include "pipeline/core/project.h"
#include "pipeline/core/video_source.h"
#include "pipeline/live/pose_track.h"

namespace fresco {

class SessionRecorder {
 public:
  // Creates DIR and DIR/frames. Errors name the folder.
  Status Start(const std::string& dir, const Project& live_project);
  // Writes the frame (PNG, atomically) and keeps its pose.
  Status Add(const Frame& frame, const Rigid3d& cam_from_world);
  // Writes poses.txt, tracker_poses.txt and, last, project.json (all atomically).
  Status Finish(const std::vector<TimedPose>& tracker_poses);
  int frames() const { return static_cast<int>(poses_.size()); }

 private:
  std::string dir_;
  Project project_;
  std::vector<PosedImage> poses_;
};

}  // namespace fresco
