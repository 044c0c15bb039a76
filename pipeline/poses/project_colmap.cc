#include "pipeline/poses/project_colmap.h"

#include <algorithm>
#include <filesystem>
#include <map>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/image_io.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

std::string Stem(const std::string& name) { return fs::path(name).stem().string(); }

}  // namespace

bool CentresLookOrdered(const std::vector<Eigen::Vector3d>& centres) {
  const size_t n = centres.size();
  if (n < 3) return false;
  std::vector<double> steps, any;
  for (size_t i = 1; i < n; ++i) steps.push_back((centres[i] - centres[i - 1]).norm());
  // Pairs a fixed stride apart stand for all pairs (at most ~n of them).
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; j += std::max<size_t>(1, n / 16)) {
      any.push_back((centres[i] - centres[j]).norm());
    }
  }
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  return median(steps) < median(any) / 3.0;
}

std::vector<int> SelectKeyframes(const std::vector<const Rigid3d*>& poses, double step_m,
                                 double rotation_deg) {
  std::vector<int> keyframes;
  const Rigid3d* last = nullptr;
  const int n = static_cast<int>(poses.size());
  for (int i = 0; i < n; ++i) {
    const Rigid3d* pose = poses[i];
    bool keep = pose == nullptr || last == nullptr || i == n - 1;
    if (!keep) {
      keep = (pose->Centre() - last->Centre()).norm() >= step_m ||
             RotationDifferenceDeg(pose->rotation, last->rotation) >= rotation_deg;
    }
    if (!keep) continue;
    keyframes.push_back(i);
    if (pose) last = pose;
  }
  return keyframes;
}

namespace {

Status CheckOptions(const ProjectColmapOptions& options) {
  if (options.every_n_frames < 1) return Status::Error("every_n_frames: must be >= 1");
  if (options.max_frames < 0) return Status::Error("max_frames: must be >= 0");
  if (options.scene_size_m < 0) return Status::Error("scene_size_m: must be >= 0");
  if (!(options.keyframe_step_rel >= 0)) return Status::Error("keyframe_step_rel: must be >= 0");
  if (!(options.keyframe_rotation_deg >= 0)) {
    return Status::Error("keyframe_rotation_deg: must be >= 0");
  }
  return Status::Ok();
}

// The project's capture, its one camera and the scene's size (given, or its extent).
Status LoadProjectCapture(const Project& project, const ProjectColmapOptions& options,
                          ProjectColmap* result) {
  CaptureLoadOptions load;
  load.load_scene = options.scene_size_m == 0.0 || options.load_scene;
  load.require_poses = false;
  FRESCO_RETURN_IF_ERROR(LoadCapture(project, load, &result->capture));
  const Capture& capture = result->capture;
  if (capture.cameras.size() != 1) {
    return Status::Error(project.camera + ": COLMAP needs one camera for all frames, found " +
                         std::to_string(capture.cameras.size()));
  }
  result->camera = capture.cameras.begin()->second;
  if (options.scene_size_m > 0) {
    result->scene_size_m = options.scene_size_m;
    return Status::Ok();
  }
  Eigen::Vector3d lo, hi;
  capture.scene.Bounds(&lo, &hi);
  result->scene_size_m = (hi - lo).norm();
  if (!(result->scene_size_m > 0)) {
    return Status::Error(project.scene +
                         ": the scene has no extent (its size sets the "
                         "position threshold)");
  }
  return Status::Ok();
}

// The frames, as image files: a folder's own (all of them), or a video's written to
// out_dir/images (every_n_frames, up to max_frames); their folder in `image_path`.
Status FrameImages(const Project& project, const ProjectColmapOptions& options,
                   const std::vector<std::string>& folder_names, Capture* capture,
                   std::string* image_path, std::vector<Frame>* frames) {
  if (!folder_names.empty()) {
    *image_path = project.Resolve(project.video);
    for (size_t i = 0; i < folder_names.size(); ++i) {
      Frame f;
      f.index = static_cast<int>(i);
      f.name = folder_names[i];
      frames->push_back(f);
    }
    return Status::Ok();
  }
  *image_path = (fs::path(options.out_dir) / "images").string();
  FRESCO_RETURN_IF_ERROR(MakeDirectories(*image_path));
  Frame frame;
  Status status;
  for (int index = 0; capture->video->Next(&frame, &status); ++index) {
    const bool keep = index % options.every_n_frames == 0;
    if (!keep) continue;
    Frame f;
    f.index = frame.index;
    f.name = frame.name;
    if (fs::path(f.name).extension().empty()) f.name += ".png";
    FRESCO_RETURN_IF_ERROR(WriteImageAtomic((fs::path(*image_path) / f.name).string(), frame.bgr));
    frames->push_back(f);
    if (options.max_frames > 0 && static_cast<int>(frames->size()) >= options.max_frames) break;
  }
  return status;
}

// The frames offered to COLMAP, each with its given pose (if any).
std::vector<ProjectColmapFrame> OfferedFrames(const std::vector<Frame>& frames, bool from_folder,
                                              const Capture& capture,
                                              const ProjectColmapOptions& options) {
  std::vector<ProjectColmapFrame> offered;
  for (size_t i = 0; i < frames.size(); ++i) {
    // Exported frames were already subsampled.
    if (from_folder && static_cast<int>(i) % options.every_n_frames != 0) continue;
    if (options.max_frames > 0 && static_cast<int>(offered.size()) >= options.max_frames) break;
    Frame lookup = frames[i];
    lookup.name = !from_folder ? Stem(frames[i].name) : frames[i].name;
    ProjectColmapFrame pf;
    pf.name = frames[i].name;
    pf.index = frames[i].index;
    pf.given = capture.PoseForFrame(lookup);
    offered.push_back(pf);
  }
  return offered;
}

// A video file is a sequence; a folder is when its given poses say so. In a sequence the
// keyframes are selected by the given poses; otherwise every frame is one. Returns whether
// the frames are ordered.
bool SelectOffered(const std::vector<ProjectColmapFrame>& offered, bool from_folder,
                   const ProjectColmapOptions& options, double scene_size_m,
                   std::vector<int>* selected) {
  std::vector<const Rigid3d*> given_poses;
  std::vector<Eigen::Vector3d> given_centres;
  for (const ProjectColmapFrame& f : offered) {
    given_poses.push_back(f.given ? &f.given->cam_from_world : nullptr);
    if (f.given) given_centres.push_back(f.given->cam_from_world.Centre());
  }
  const bool ordered = !from_folder || CentresLookOrdered(given_centres);
  selected->resize(offered.size());
  for (size_t i = 0; i < offered.size(); ++i) (*selected)[i] = static_cast<int>(i);
  // With an earlier model, the keyframes are chosen as its run chose them: the frames of the
  // model between them are judged as that run judged them.
  if (ordered) {
    *selected = SelectKeyframes(given_poses, options.keyframe_step_rel * scene_size_m,
                                options.keyframe_rotation_deg);
  }
  return ordered;
}

// The frames COLMAP is given by name: the keyframes it reconstructs from and the others it
// registers afterwards, each matched with the keyframes `pairs` pairs it with.
struct ColmapFrames {
  std::vector<std::string> keyframes, others;
  std::vector<std::pair<std::string, std::string>> pairs;
};

// The frames the result reports (keyframes marked) and, when the others are registered
// afterwards, their names, each matched with the two keyframes on either side of it.
void SplitOffered(const std::vector<ProjectColmapFrame>& offered, const std::vector<int>& selected,
                  const ProjectColmapOptions& options, ProjectColmap* result, ColmapFrames* names) {
  const bool register_others = options.register_other_frames && options.existing_model.empty() &&
                               selected.size() < offered.size();
  for (size_t i = 0, k = 0; i < offered.size(); ++i) {
    while (k < selected.size() && selected[k] < static_cast<int>(i)) ++k;
    const bool keyframe = k < selected.size() && selected[k] == static_cast<int>(i);
    if (keyframe || register_others || !options.existing_model.empty()) {
      result->frames.push_back(offered[i]);
      result->frames.back().keyframe = keyframe;
    }
    if (keyframe || !register_others) continue;
    names->others.push_back(offered[i].name);
    for (int side : {-2, -1, 0, 1})  // selected[k] is the first keyframe after frame i
      if (const int j = static_cast<int>(k) + side; j >= 0 && j < static_cast<int>(selected.size()))
        names->pairs.emplace_back(offered[i].name, offered[selected[j]].name);
  }
}

// The earlier run's model, given in the options.
Status ReadEarlierModel(const std::string& existing_model, ColmapRunResult* run) {
  FRESCO_RETURN_IF_ERROR(ReadColmapModel(existing_model, &run->model));
  run->registered = static_cast<int>(run->model.images.size());
  run->models = 1;
  run->program = "(earlier run: " + existing_model + ")";
  return Status::Ok();
}

// Each reported frame's image in COLMAP's model, by name.
void LinkModelImages(ProjectColmap* result) {
  std::map<std::string, const PosedImage*> by_name;
  for (const PosedImage& image : result->run.model.images) by_name[image.name] = &image;
  for (ProjectColmapFrame& f : result->frames) {
    const auto it = by_name.find(f.name);
    if (it != by_name.end()) f.colmap = it->second;
  }
}

}  // namespace

Status RunColmapOnProject(const Project& project, const ProjectColmapOptions& options,
                          ProjectColmap* result) {
  FRESCO_RETURN_IF_ERROR(CheckOptions(options));
  FRESCO_RETURN_IF_ERROR(LoadProjectCapture(project, options, result));
  Capture& capture = result->capture;

  const std::vector<std::string> folder_names = capture.video->FrameNames();
  const bool from_folder = !folder_names.empty();
  std::string image_path;
  std::vector<Frame> frames;  // name and index only
  FRESCO_RETURN_IF_ERROR(
      FrameImages(project, options, folder_names, &capture, &image_path, &frames));
  const std::vector<ProjectColmapFrame> offered =
      OfferedFrames(frames, from_folder, capture, options);
  std::vector<int> selected;
  const bool ordered =
      SelectOffered(offered, from_folder, options, result->scene_size_m, &selected);
  ColmapFrames names;
  for (int i : selected) names.keyframes.push_back(offered[i].name);
  SplitOffered(offered, selected, options, result, &names);
  if (names.keyframes.size() < 3) {
    return Status::Error(project.video + ": COLMAP needs at least 3 frames, the project has " +
                         std::to_string(names.keyframes.size()) +
                         " (after every_n_frames/max_frames)");
  }

  if (!options.existing_model.empty()) {
    FRESCO_RETURN_IF_ERROR(ReadEarlierModel(options.existing_model, &result->run));
  } else {
    ColmapRunOptions run = options.colmap;
    run.workspace = options.out_dir;
    run.image_path = image_path;
    run.image_names = names.keyframes;
    run.camera = result->camera;
    run.ordered = ordered;
    run.register_names = names.others;
    run.register_pairs = names.pairs;
    FRESCO_RETURN_IF_ERROR(RunColmap(run, &result->run).Reclassified(StatusKind::kFailed));
  }
  result->run.frames_offered = static_cast<int>(offered.size());
  result->run.keyframes = static_cast<int>(names.keyframes.size());
  LinkModelImages(result);
  return Status::Ok();
}

std::vector<VerifyFrameInput> VerifyInputs(const ProjectColmap& colmap) {
  std::vector<VerifyFrameInput> inputs;
  for (const ProjectColmapFrame& f : colmap.frames) {
    int observations = -1;
    if (f.colmap && !f.colmap->point3d_ids.empty())
      observations =
          static_cast<int>(std::count_if(f.colmap->point3d_ids.begin(), f.colmap->point3d_ids.end(),
                                         [](long long id) { return id >= 0; }));
    inputs.push_back({f.name, f.given ? &f.given->cam_from_world : nullptr,
                      f.colmap ? &f.colmap->cam_from_world : nullptr, f.keyframe, observations});
  }
  return inputs;
}

}  // namespace fresco
