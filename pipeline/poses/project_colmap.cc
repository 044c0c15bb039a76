#include "pipeline/poses/project_colmap.h"

#include <filesystem>
#include <map>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/image_io.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

std::string Stem(const std::string& name) { return fs::path(name).stem().string(); }

}  // namespace

Status RunColmapOnProject(const Project& project, const ProjectColmapOptions& options,
                          ProjectColmap* result, bool* bad_input) {
  *bad_input = true;
  if (options.every_n_frames < 1) return Status::Error("every_n_frames: must be >= 1");
  if (options.max_frames < 0) return Status::Error("max_frames: must be >= 0");
  if (options.scene_size_m < 0) return Status::Error("scene_size_m: must be >= 0");
  CaptureLoadOptions load;
  load.load_scene = options.scene_size_m == 0.0 || options.load_scene;
  load.require_poses = false;
  FRESCO_RETURN_IF_ERROR(LoadCapture(project, load, &result->capture));
  Capture& capture = result->capture;
  if (capture.cameras.size() != 1) {
    return Status::Error(project.camera + ": COLMAP needs one camera for all frames, found " +
                         std::to_string(capture.cameras.size()));
  }
  result->camera = capture.cameras.begin()->second;
  if (options.scene_size_m > 0) {
    result->scene_size_m = options.scene_size_m;
  } else {
    Eigen::Vector3d lo, hi;
    capture.scene.Bounds(&lo, &hi);
    result->scene_size_m = (hi - lo).norm();
    if (!(result->scene_size_m > 0)) {
      return Status::Error(project.scene +
                           ": the scene has no extent (its size sets the "
                           "position threshold)");
    }
  }

  // The frames, as image files.
  const std::vector<std::string> folder_names = capture.video->FrameNames();
  std::string image_path;
  std::vector<Frame> frames;  // name and index only
  if (!folder_names.empty()) {
    image_path = project.Resolve(project.video);
    for (size_t i = 0; i < folder_names.size(); ++i) {
      Frame f;
      f.index = static_cast<int>(i);
      f.name = folder_names[i];
      frames.push_back(f);
    }
  } else {
    image_path = (fs::path(options.out_dir) / "images").string();
    FRESCO_RETURN_IF_ERROR(MakeDirectories(image_path));
    Frame frame;
    Status status;
    for (int index = 0; capture.video->Next(&frame, &status); ++index) {
      const bool keep = index % options.every_n_frames == 0;
      if (!keep) continue;
      Frame f;
      f.index = frame.index;
      f.name = frame.name;
      if (fs::path(f.name).extension().empty()) f.name += ".png";
      FRESCO_RETURN_IF_ERROR(WriteImageAtomic((fs::path(image_path) / f.name).string(), frame.bgr));
      frames.push_back(f);
      if (options.max_frames > 0 && static_cast<int>(frames.size()) >= options.max_frames) break;
    }
    if (!status.ok()) return status;
  }
  std::vector<std::string> names;
  int kept = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    // Exported frames were already subsampled.
    if (!folder_names.empty() && static_cast<int>(i) % options.every_n_frames != 0) continue;
    if (options.max_frames > 0 && kept >= options.max_frames) break;
    ++kept;
    Frame lookup = frames[i];
    lookup.name = folder_names.empty() ? Stem(frames[i].name) : frames[i].name;
    ProjectColmapFrame pf;
    pf.name = frames[i].name;
    pf.index = frames[i].index;
    pf.given = capture.PoseForFrame(lookup);
    result->frames.push_back(pf);
    names.push_back(frames[i].name);
  }
  if (names.size() < 3) {
    return Status::Error(project.video + ": COLMAP needs at least 3 frames, the project has " +
                         std::to_string(names.size()) + " (after every_n_frames/max_frames)");
  }

  if (!options.existing_model.empty()) {
    FRESCO_RETURN_IF_ERROR(ReadColmapModel(options.existing_model, &result->run.model));
    result->run.registered = static_cast<int>(result->run.model.images.size());
    result->run.models = 1;
    result->run.program = "(earlier run: " + options.existing_model + ")";
  } else {
    *bad_input = false;
    ColmapRunOptions run = options.colmap;
    run.workspace = options.out_dir;
    run.image_path = image_path;
    run.image_names = names;
    run.camera = result->camera;
    FRESCO_RETURN_IF_ERROR(RunColmap(run, &result->run));
  }
  *bad_input = false;
  std::map<std::string, const PosedImage*> by_name;
  for (const PosedImage& image : result->run.model.images) by_name[image.name] = &image;
  for (ProjectColmapFrame& f : result->frames) {
    const auto it = by_name.find(f.name);
    if (it != by_name.end()) f.colmap = it->second;
  }
  return Status::Ok();
}

std::vector<VerifyFrameInput> VerifyInputs(const ProjectColmap& colmap) {
  std::vector<VerifyFrameInput> inputs;
  for (const ProjectColmapFrame& f : colmap.frames) {
    inputs.push_back({f.name, f.given ? &f.given->cam_from_world : nullptr,
                      f.colmap ? &f.colmap->cam_from_world : nullptr});
  }
  return inputs;
}

}  // namespace fresco
