// Attaching a calibrated camera to the open project (the Calibration panel's "Attach to
// project"): first the checks, which change nothing — the camera's size against the frames
// of the project's video and the lens's plausibility — then, once the user confirms, the
// project's camera path as an undoable edit. No ImGui: tests call these directly.
#pragma once

#include <string>

#include "pipeline/core/camera.h"
#include "pipeline/core/project.h"
#include "pipeline/core/status.h"

namespace fresco {

struct AppState;

// Whether `camera` could be a real lens, `what` naming it in the errors: Camera::Validate,
// then the principal point inside the image, near-square pixels (0.5 <= fx / fy <= 2), a
// field of view across the image between 1 and 170 degrees, and a distortion that does not
// fold over before the image's corners.
Status CheckLensPlausible(const Camera& camera, const std::string& what);

// What Attach would attach, checked before anything changes.
struct CameraAttachCheck {
  Camera camera;           // as read from the file
  int frame_width_px = 0;  // the project's frames (0: not known, e.g. a live video)
  int frame_height_px = 0;
  std::string summary;  // one line for the confirmation ("1024x768 OPENCV8, ...")
};

// Reads `cameramodel_path` and checks it against stream `stream` of `project` (its first
// frame's size; a live video is not opened) and CheckLensPlausible. Errors name the file and
// both sizes: "cam0.cameramodel: the camera is 1024x768 but the project's frames are 640x480
// (frames/000000.png)".
Status CheckCameraForProject(const std::string& cameramodel_path, int stream,
                             const Project& project, CameraAttachCheck* check);

// Points the open project's camera at `cameramodel_path` (relative to the project's folder
// when it is below it): `camera` of a version-1 project, `streams[stream].camera` of a
// version-2 one. Undo restores the previous camera. Call CheckCameraForProject first.
Status AttachCameraToProject(const std::string& cameramodel_path, int stream, AppState* state);

}  // namespace fresco
