#include "ui/core/camera_attach.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "pipeline/core/cameramodel_io.h"
#include "pipeline/core/video_source.h"
#include "ui/core/app_state.h"

namespace fresco {
namespace {

std::string Size(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

std::string Number(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

// The field of view across the image's width, degrees.
double FieldOfViewDeg(const Camera& camera) {
  return 2 * std::atan(0.5 * camera.width / camera.fx) * 180 / M_PI;
}

}  // namespace

Status CheckLensPlausible(const Camera& camera, const std::string& what) {
  if (Status s = camera.Validate(what); !s.ok()) return s;
  const std::string size = Size(camera.width, camera.height);
  if (camera.cx < 0 || camera.cx > camera.width - 1 || camera.cy < 0 ||
      camera.cy > camera.height - 1)
    return Status::Error(what + ": the principal point (" + Number("%.1f", camera.cx) + ", " +
                         Number("%.1f", camera.cy) + ") lies outside the " + size +
                         " image: not a plausible lens");
  const double aspect = camera.fx / camera.fy;
  if (aspect < 0.5 || aspect > 2)
    return Status::Error(what + ": fx / fy is " + Number("%.2f", aspect) +
                         " (plausible: 0.5 to 2): not a plausible lens");
  const double fov_deg = FieldOfViewDeg(camera);
  if (fov_deg < 1 || fov_deg > 170)
    return Status::Error(what + ": fx " + Number("%.1f", camera.fx) +
                         " px gives a field of view of " + Number("%.1f", fov_deg) +
                         " deg across " + std::to_string(camera.width) +
                         " px (plausible: 1 to 170): not a plausible lens");
  const double corners[4][2] = {{0, 0},
                                {camera.width - 1.0, 0},
                                {0, camera.height - 1.0},
                                {camera.width - 1.0, camera.height - 1.0}};
  for (const auto& c : corners) {
    Eigen::Vector2d normalized;
    if (!camera.Unproject(Eigen::Vector2d(c[0], c[1]), &normalized, 1e-3))
      return Status::Error(what + ": the distortion folds over before the image's corner (" +
                           Number("%.0f", c[0]) + ", " + Number("%.0f", c[1]) +
                           "): not a plausible lens");
  }
  return Status::Ok();
}

Status CheckCameraForProject(const std::string& cameramodel_path, int stream,
                             const Project& project, CameraAttachCheck* check) {
  if (cameramodel_path.empty()) return Status::Error("save the calibration first");
  const std::vector<StreamSpec> streams = project.Streams();
  if (stream < 0 || stream >= static_cast<int>(streams.size()))
    return Status::Error("the project has no stream " + std::to_string(stream));
  CameraAttachCheck result;
  CameraModelFile model;
  if (Status s = ReadCameraModel(cameramodel_path, &model); !s.ok()) return s;
  result.camera = model.camera;
  const Camera& camera = result.camera;
  if (Status s = CheckLensPlausible(camera, cameramodel_path); !s.ok()) return s;
  const double fov_deg = FieldOfViewDeg(camera);
  result.summary = "the camera is " + Size(camera.width, camera.height) + ", fx " +
                   Number("%.1f", camera.fx) + " px (" + Number("%.0f", fov_deg) + " deg across)";
  const std::string& video = streams[stream].video;
  if (IsUrlOrDevice(video)) {
    result.summary += "; the frames of a live video are checked when it runs";
  } else {
    std::unique_ptr<VideoSource> source;
    if (Status s = OpenVideoSource(project.Resolve(video), &source); !s.ok()) return s;
    Frame frame;
    Status read;
    if (!source->Next(&frame, &read))
      return Status::Error(project.StreamKey(stream, "video") + ": " +
                           (read.ok() ? "holds no frame" : read.message()));
    result.frame_width_px = frame.bgr.cols;
    result.frame_height_px = frame.bgr.rows;
    const std::string frames = Size(frame.bgr.cols, frame.bgr.rows);
    if (frame.bgr.cols != camera.width || frame.bgr.rows != camera.height)
      return Status::Error(cameramodel_path + ": the camera is " +
                           Size(camera.width, camera.height) + " but the project's frames are " +
                           frames + " ('" + frame.name + "'): not attached");
    result.summary += ", as the project's frames";
  }
  *check = std::move(result);
  return Status::Ok();
}

Status AttachCameraToProject(const std::string& cameramodel_path, int stream, AppState* state) {
  namespace fs = std::filesystem;
  if (!state->has_project) return Status::Error("no project open");
  if (cameramodel_path.empty()) return Status::Error("save the calibration first");
  const int streams = static_cast<int>(state->project.Streams().size());
  if (state->project.fresco_version >= 2 && (stream < 0 || stream >= streams))
    return Status::Error("the project has no stream " + std::to_string(stream));
  const fs::path project_dir = fs::absolute(state->project.file_path).parent_path();
  const fs::path model = fs::absolute(cameramodel_path).lexically_normal();
  const fs::path relative = model.lexically_relative(project_dir);
  const bool below = !relative.empty() && relative.begin()->string() != "..";
  const std::string written = below ? relative.string() : model.string();
  state->BeginEdit();
  if (state->project.fresco_version >= 2) {
    state->project.streams[stream].camera = written;
    state->message = "streams[" + std::to_string(stream) + "].camera: " + written;
  } else {
    state->project.camera = written;
    state->message = "camera: " + written;
  }
  state->message += " (from the calibration; undo restores the previous camera)";
  return Status::Ok();
}

}  // namespace fresco
