// Records a live session as a normal project for replay: DIR/frames/%06d.png (each frame
// painted, i.e. delivered with a pose; dropped frames are not recorded), DIR/poses.txt (TUM:
// each frame's pose as matched, interpolated at its time, the frame's video time as the
// timestamp; TUM poses match frames in order), DIR/tracker_poses.txt (every pose the
// tracker sent, its own clock) and DIR/project.json (the live project's scene, camera and
// settings with video "frames/", poses "poses.txt", time_offset_s 0 and estimation off).
// `fresco run DIR/project.json` then replays what was painted live.
// The frames go, with plain writes, into a staging folder that replaces DIR/frames in
// Finish (StagedFolder): no fsync and rename per frame on the painting thread, and a run
// that stops before Finish leaves an earlier recording in DIR as it was.
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/poses.h"
#include "pipeline/core/project.h"
#include "pipeline/core/video_source.h"
#include "pipeline/live/pose_track.h"

namespace fresco {

class SessionRecorder {
 public:
  // Creates DIR and the staging folder for DIR/frames. Errors name the folder.
  Status Start(const std::string& dir, const Project& live_project);
  // Writes the frame (PNG) into the staging folder and keeps its pose.
  Status Add(const Frame& frame, const Rigid3d& cam_from_world);
  // Removes an earlier DIR/project.json, writes poses.txt and tracker_poses.txt
  // (atomically), swaps the staged frames in as DIR/frames and, last, writes project.json.
  Status Finish(const std::vector<TimedPose>& tracker_poses);
  int frames() const { return static_cast<int>(poses_.size()); }

 private:
  std::string dir_;
  StagedFolder frames_;
  Project project_;
  std::vector<PosedImage> poses_;
};

}  // namespace fresco
