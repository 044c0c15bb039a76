// Small synthetic captures broken one way each, the same for every client of the painting
// job (`fresco run`, `fresco bench`, the app's worker): the issue-22 comparison and the job
// layer's own tests use them.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "pipeline/core/poses.h"

namespace fresco::testing {

enum class BadCapture {
  kFramesSmallerThanCamera,  // every frame 80x60, the camera 160x120
  kUnknownCameraId,          // frame 3's pose names CAMERA_ID 7 (the camera file has id 1)
  kMissingPose,              // frame 3 (000003.png) has no pose in images.txt
  kCorruptImage,             // frame 5 (000005.png) is not a PNG
};

// The good capture: 12 frames of the cube room, 160x120, COLMAP poses (made once).
std::string GoodCaptureDir();
constexpr int kGoodCaptureFrames = 12;

// A fresh copy of the good capture broken as `how`; returns its project.json.
std::string MakeBadCapture(BadCapture how);
// A version-2 project with two streams over the good capture's frames: stream 0 with all
// its poses, stream 1 with frame 3's pose missing (24 frames, 23 with a pose). Returns its
// project file.
std::string MakeTwoStreamCapture();

// The frames-smaller-than-the-camera capture as a live project (live.json beside it): its
// frames folder matched by time to poses from a feed at tcp://127.0.0.1:`pose_port`, the time
// offset estimated over 8 frames before painting. `truth`: the poses a tracker sends (frame
// i's at i / 30 s).
struct LiveBadCapture {
  std::string project;
  std::vector<PosedImage> truth;
  std::string first_frame_error;  // the frame policy's message for its first frame
};
LiveBadCapture MakeLiveSmallFramesCapture(int pose_port);

// "frames smaller than the camera", ... (test output).
std::string Describe(BadCapture how);
std::vector<BadCapture> AllBadCaptures();
// For gtest's messages (parameterized tests).
inline void PrintTo(BadCapture how, std::ostream* os) { *os << Describe(how); }

}  // namespace fresco::testing
