// Opens a project's live inputs, in the order a live capture needs: the pose feed first
// (tcp:// connects, udp:// and fifo:// listen), then the video (opening a stream waits for
// its first packets), then the frame matching (live_frames.h). Shared by `fresco run` and
// the app. Errors name the address or file ("udp://127.0.0.1:5000: cannot open the stream
// within 10 s ...") and are bad input (exit 2).
#pragma once

#include <memory>

#include "pipeline/core/capture.h"
#include "pipeline/core/project.h"
#include "pipeline/live/live_frames.h"
#include "pipeline/live/pose_feed.h"
#include "pipeline/live/pose_track.h"

namespace fresco {

// True when a stream's video or poses are live (a camera, a stream or a pose feed).
// OpenLiveInputs reads a project with one stream (Project::ForStream(0) of a version-2 file).
bool IsLiveProject(const Project& project);

struct LiveInputs {
  std::unique_ptr<PoseFeed> feed;    // poses from a feed, or
  std::shared_ptr<PoseTrack> track;  // poses from a TUM file, matched by time
  std::unique_ptr<LiveFrames> frames;
  const Camera* camera = nullptr;  // the project's only camera
};

// `capture` loaded with open_video false; `estimator` scores the time offset when
// live.estimate_offset or live.track_offset is on (pipeline/run/offset_estimator.h paints
// for it; empty: the offset is not estimated).
Status OpenLiveInputs(const Project& project, const Capture& capture, OffsetEstimator estimator,
                      bool keep_tracker_poses, LiveInputs* inputs);

}  // namespace fresco
