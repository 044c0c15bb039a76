// A project's inputs loaded and matched: scene, cameras, the video stream and one pose per
// frame where there is one. Errors name the file and what is wrong (missing file, NaN pose,
// an image listed in the poses but missing from the video folder, ...).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pipeline/core/camera.h"
#include "pipeline/core/poses.h"
#include "pipeline/core/project.h"
#include "pipeline/core/scene.h"
#include "pipeline/core/status.h"
#include "pipeline/core/video_source.h"

namespace fresco {

struct Capture {
  Scene scene;
  std::map<int, Camera> cameras;        // by CAMERA_ID (a .cameramodel gives id 1)
  std::vector<PosedImage> poses;        // as read
  std::vector<PosedImage> truth_poses;  // empty unless the project names truth poses
  std::unique_ptr<VideoSource> video;
  // For frame names known up front (folders): frame name -> index into `poses`.
  std::map<std::string, int> pose_by_name;
  // Pose name without extension -> index into `poses` (-1 when two poses share it): frames
  // whose extension differs from the listed name ("a.png" listed, "a.jpg" on disk) still match.
  std::map<std::string, int> pose_by_stem;
  bool poses_are_tum = false;  // TUM poses match frames in order
  // Per pose (index into `poses`; empty or shorter: none): the frame's Frame::movers, found
  // before painting (paint_job.h).
  std::vector<cv::Mat> movers;

  // The pose for a frame (by name for COLMAP, by order for TUM); nullptr when none.
  const PosedImage* PoseForFrame(const Frame& frame) const;
  // The camera a pose uses (its CAMERA_ID, or the only camera).
  const Camera* CameraFor(const PosedImage& pose) const;
};

struct CaptureLoadOptions {
  bool load_scene = true;
  bool open_video = true;
  // With open_video: also a live stream's video (one whose video or poses are live: a
  // camera, a stream URL or a pose feed). False: only file streams open theirs (a live
  // video opens after its pose feed connects: live_input.h).
  bool open_live_video = true;
  // When false, a poses file that holds no poses is accepted (`fresco poses bootstrap` makes
  // the poses for such a project).
  bool require_poses = true;
  // Which of the project's video streams (Project::Streams()) to load. -1: the project's
  // only stream; a project with several is then an error naming `streams` (callers that
  // read one stream refuse them). Messages name a version-2 stream's keys by JSON path
  // ("streams[1].video").
  int stream = -1;
};

// Loads the scene (when asked) and one video stream's cameras, poses and video.
Status LoadCapture(const Project& project, const CaptureLoadOptions& options, Capture* capture);

// A frame must have its camera's size (painting samples it through the camera's rays): an
// error "VIDEO: frame 'NAME' is WxH but the camera is WxH" otherwise. `fresco run`, `fresco
// bench` and the app all stop on it.
Status CheckFrameSize(const Frame& frame, const Camera& camera, const std::string& video);
// Every video stream of the project, in order: the scene is loaded once, into (*streams)[0]
// (the others' scenes stay empty); each stream's files as LoadCapture loads them.
Status LoadStreamCaptures(const Project& project, const CaptureLoadOptions& options,
                          std::vector<Capture>* streams);

}  // namespace fresco
