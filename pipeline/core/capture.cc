// Loads a project's inputs and checks that they fit together before any painting starts:
// every file exists, every pose's camera exists, and every image the COLMAP poses list is a
// frame of the video folder.
#include "pipeline/core/capture.h"

#include <algorithm>
#include <filesystem>
#include <set>
#include <stdexcept>

#include "pipeline/core/cameramodel_io.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

std::string Stem(const std::string& name) { return fs::path(name).stem().string(); }

// The project file as messages name it.
std::string ProjectName(const Project& project) {
  return project.file_path.empty() ? std::string("project") : project.file_path;
}

// "p.json: camera: 'sparse/cameras.txt' does not exist (/abs/sparse/cameras.txt)".
Status CheckExists(const Project& project, const std::string& key, const std::string& written) {
  if (IsUrlOrDevice(written)) return Status::Ok();
  const std::string resolved = project.Resolve(written);
  std::error_code ec;
  if (!fs::exists(resolved, ec)) {
    return Status::Error(ProjectName(project) + ": " + key + ": '" + written +
                         "' does not exist (" + resolved + ")");
  }
  return Status::Ok();
}

// A missing key would be caught by ParseProject; this guards hand-built Projects.
Status CheckNotEmpty(const Project& project, const std::string& key, const std::string& value) {
  if (value.empty()) return Status::Error(ProjectName(project) + ": " + key + ": empty path");
  return Status::Ok();
}

Status CheckCameras(const StreamSpec& stream, const Capture& capture) {
  if (capture.cameras.empty()) {
    return Status::Error(stream.camera + ": holds no camera");
  }
  if (capture.poses_are_tum) {
    if (capture.cameras.size() != 1) {
      return Status::Error(stream.poses + ": TUM poses name no camera, but " + stream.camera +
                           " holds " + std::to_string(capture.cameras.size()) +
                           " cameras (give a file with one)");
    }
    return Status::Ok();
  }
  for (const PosedImage& pose : capture.poses) {
    if (!capture.cameras.count(pose.camera_id)) {
      return Status::Error(stream.poses + ": image '" + pose.name + "' (IMAGE_ID " +
                           std::to_string(pose.image_id) + "): CAMERA_ID " +
                           std::to_string(pose.camera_id) + " is not in " + stream.camera);
    }
  }
  return Status::Ok();
}

// Maps each pose's name (and, where unambiguous, its stem) to its index.
void IndexPoseNames(Capture* capture) {
  capture->pose_by_name.clear();
  capture->pose_by_stem.clear();
  for (int i = 0; i < static_cast<int>(capture->poses.size()); ++i) {
    const std::string& name = capture->poses[i].name;
    capture->pose_by_name[name] = i;
    const std::string stem = Stem(name);
    const auto it = capture->pose_by_stem.find(stem);
    if (it == capture->pose_by_stem.end()) {
      capture->pose_by_stem[stem] = i;
    } else {
      it->second = -1;  // two poses share the stem: match those by exact name only
    }
  }
}

// Every image the COLMAP poses list must be a frame of the video folder (by name, or by
// stem when the extension differs); frames then map to their poses by name.
Status MatchFolderFrames(const StreamSpec& stream, Capture* capture) {
  const std::vector<std::string> frame_names = capture->video->FrameNames();
  if (frame_names.empty() || capture->poses_are_tum) return Status::Ok();
  std::set<std::string> names(frame_names.begin(), frame_names.end());
  std::map<std::string, int> stem_count;
  for (const std::string& name : frame_names) ++stem_count[Stem(name)];
  for (const PosedImage& pose : capture->poses) {
    const std::string file_name = fs::path(pose.name).filename().string();
    if (names.count(pose.name) || names.count(file_name)) continue;
    if (stem_count[Stem(pose.name)] == 1) continue;
    return Status::Error(stream.poses + ": image '" + pose.name +
                         "' is listed but missing from video folder " + stream.video);
  }
  // Poses named with a subfolder ("images/000012.png") match frames by file name.
  for (int i = 0; i < static_cast<int>(capture->poses.size()); ++i) {
    const std::string file_name = fs::path(capture->poses[i].name).filename().string();
    if (names.count(file_name)) capture->pose_by_name.emplace(file_name, i);
  }
  return Status::Ok();
}

}  // namespace

const PosedImage* Capture::PoseForFrame(const Frame& frame) const {
  if (poses_are_tum) {
    if (frame.index < 0 || frame.index >= static_cast<int>(poses.size())) return nullptr;
    return &poses[frame.index];
  }
  const auto by_name = pose_by_name.find(frame.name);
  if (by_name != pose_by_name.end()) return &poses[by_name->second];
  const auto by_stem = pose_by_stem.find(Stem(frame.name));
  if (by_stem != pose_by_stem.end() && by_stem->second >= 0) return &poses[by_stem->second];
  return nullptr;
}

const Camera* Capture::CameraFor(const PosedImage& pose) const {
  const auto it = cameras.find(pose.camera_id);
  if (it != cameras.end()) return &it->second;
  if (cameras.size() == 1) return &cameras.begin()->second;
  return nullptr;
}

Status LoadCapture(const Project& project, const CaptureLoadOptions& options, Capture* capture) {
  const std::vector<StreamSpec> streams = project.Streams();
  if (options.stream < 0) FRESCO_RETURN_IF_ERROR(CheckOneStream(project, "this command"));
  const int index = std::max(options.stream, 0);
  if (index >= static_cast<int>(streams.size())) {
    throw std::out_of_range("LoadCapture: no stream " + std::to_string(index));
  }
  const StreamSpec& stream = streams[index];
  const auto key = [&](const char* name) { return project.StreamKey(index, name); };
  Capture result;
  // Every file the project names must exist before anything is parsed.
  FRESCO_RETURN_IF_ERROR(CheckNotEmpty(project, key("camera"), stream.camera));
  FRESCO_RETURN_IF_ERROR(CheckNotEmpty(project, key("poses"), stream.poses));
  FRESCO_RETURN_IF_ERROR(CheckNotEmpty(project, key("video"), stream.video));
  if (options.load_scene) {
    FRESCO_RETURN_IF_ERROR(CheckNotEmpty(project, "scene", project.scene));
    FRESCO_RETURN_IF_ERROR(CheckExists(project, "scene", project.scene));
  }
  FRESCO_RETURN_IF_ERROR(CheckExists(project, key("camera"), stream.camera));
  FRESCO_RETURN_IF_ERROR(CheckExists(project, key("poses"), stream.poses));
  FRESCO_RETURN_IF_ERROR(CheckExists(project, key("video"), stream.video));
  if (!project.truth.poses.empty()) {
    FRESCO_RETURN_IF_ERROR(CheckExists(project, "truth.poses", project.truth.poses));
  }

  if (options.load_scene) {
    FRESCO_RETURN_IF_ERROR(
        LoadScene(project.Resolve(project.scene), SceneLoadOptions(), &result.scene));
  }
  FRESCO_RETURN_IF_ERROR(ReadCameras(project.Resolve(stream.camera), &result.cameras));
  if (!IsUrlOrDevice(stream.poses)) {  // live poses (tcp://) arrive while running
    FRESCO_RETURN_IF_ERROR(
        ReadPoses(project.Resolve(stream.poses), &result.poses, &result.poses_are_tum));
    if (result.poses.empty() && options.require_poses) {
      return Status::Error(stream.poses + ": holds no poses");
    }
  } else {
    result.poses_are_tum = true;
  }
  if (!project.truth.poses.empty()) {
    bool truth_is_tum = false;
    FRESCO_RETURN_IF_ERROR(
        ReadPoses(project.Resolve(project.truth.poses), &result.truth_poses, &truth_is_tum));
  }
  FRESCO_RETURN_IF_ERROR(CheckCameras(stream, result));
  IndexPoseNames(&result);

  const bool live = IsUrlOrDevice(stream.video) || IsUrlOrDevice(stream.poses);
  if (options.open_video && (options.open_live_video || !live)) {
    FRESCO_RETURN_IF_ERROR(OpenVideoSource(project.Resolve(stream.video), &result.video));
    FRESCO_RETURN_IF_ERROR(MatchFolderFrames(stream, &result));
  }
  *capture = std::move(result);
  return Status::Ok();
}

Status LoadStreamCaptures(const Project& project, const CaptureLoadOptions& options,
                          std::vector<Capture>* streams) {
  const int count = static_cast<int>(project.Streams().size());
  std::vector<Capture> result(count);
  for (int i = 0; i < count; ++i) {
    CaptureLoadOptions one = options;
    one.stream = i;
    one.load_scene = options.load_scene && i == 0;
    FRESCO_RETURN_IF_ERROR(LoadCapture(project, one, &result[i]));
  }
  *streams = std::move(result);
  return Status::Ok();
}

Status CheckFrameSize(const Frame& frame, const Camera& camera, const std::string& video) {
  if (frame.bgr.cols == camera.width && frame.bgr.rows == camera.height) return Status::Ok();
  return Status::Error(video + ": frame '" + frame.name + "' is " + std::to_string(frame.bgr.cols) +
                       "x" + std::to_string(frame.bgr.rows) + " but the camera is " +
                       std::to_string(camera.width) + "x" + std::to_string(camera.height));
}

}  // namespace fresco
