// `fresco render MODEL --camera CAMERA --poses POSES --out DIR [options]`: renders a model
// (glTF, PLY or OBJ) through a camera (full lens model) at every pose, one RGBA PNG per pose
// (docs/contract.md).
// Everything is read and checked before the first image is written, so bad input never
// leaves a partial output; every image is written atomically (temp file + rename).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "app/commands.h"
#include "app/progress.h"
#include "pipeline/core/atomic_file.h"
#include "pipeline/core/cameramodel_io.h"
#include "pipeline/core/image_codecs.h"
#include "pipeline/core/poses.h"
#include "pipeline/core/scene.h"
#include "pipeline/render/renderer.h"
#include "pipeline/render/view_dependent_render.h"

namespace fresco {

namespace {

namespace fs = std::filesystem;

// width * height * N^2: the renderer needs about 60 bytes per sample (4 GB here).
constexpr double kMaxSamplesPerImage = 1 << 26;

const char kHelp[] =
    R"(Renders MODEL (glTF 2.0 .gltf/.glb, PLY .ply or OBJ .obj) through CAMERA at every pose of
POSES and writes DIR/NAME.png per pose: 8-bit RGBA at the camera's image size, alpha 255
where a surface with texture alpha >= 0.5 is seen and 0 elsewhere. A model painted with
view-dependent layers (pipeline.layers) shows, per pixel, the layers whose photos were taken
nearest the pose. Deterministic, CPU only, no display.

  CAMERA   an mrcal .cameramodel or a COLMAP cameras.txt (each image uses its CAMERA_ID;
           a single camera serves every pose)
  POSES    a COLMAP images.txt or model folder (NAME from the file, its extension replaced
           by .png, subfolders created), or a TUM trajectory (%06d.png by order, from 0)

options:
  --supersample N      N x N rays per pixel, averaged (1..4, default 1)
  --filter F           texture filter: bilinear (default) or nearest
  --near M             near clipping plane in metres (default 0.001)
  --cull-back-faces    do not draw triangles seen from behind
  --depth              also write DIR/NAME.depth.png: 16-bit camera z in millimetres
                       (0 = no surface, 65535 = 65.535 m or farther)
  --ids                also write DIR/NAME.ids.png: 8-bit RGBA, triangle id + 1 as
                       R + 256 G + 65536 B (0 = no surface), alpha 255 where a surface is seen
  --single-texture     a model with view-dependent layers: show its base-colour texture
                       only, as other viewers do
  --quiet              no progress on stderr)";

// DIR-relative output path for a COLMAP image NAME: extension replaced by `suffix`.
bool OutputName(const std::string& name, const std::string& suffix, std::string* out,
                std::string* why) {
  if (name.empty()) {
    *why = "empty NAME";
    return false;
  }
  const fs::path path(name);
  if (path.is_absolute()) {
    *why = "NAME '" + name + "' is an absolute path";
    return false;
  }
  for (const fs::path& part : path) {
    if (part == "..") {
      *why = "NAME '" + name + "' leaves the output folder ('..')";
      return false;
    }
  }
  if (!path.has_filename() || path.filename() == ".") {
    *why = "NAME '" + name + "' is not a file name";
    return false;
  }
  fs::path stem = path;
  stem.replace_extension();
  *out = stem.generic_string() + suffix;
  return true;
}

Status WritePng(const std::string& path, const cv::Mat& image) {
  std::vector<uchar> bytes;
  if (!EncodeImageBytes(".png", image, &bytes))
    return Status::Internal(path + ": could not encode the PNG");
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty()) FRESCO_RETURN_IF_ERROR(MakeDirectories(parent.string()));
  return WriteFileAtomic(path, std::string(bytes.begin(), bytes.end()));
}

cv::Mat DepthMillimetres(const cv::Mat& depth) {
  cv::Mat out(depth.size(), CV_16U);
  for (int r = 0; r < depth.rows; ++r) {
    const float* in = depth.ptr<float>(r);
    uint16_t* o = out.ptr<uint16_t>(r);
    for (int c = 0; c < depth.cols; ++c) {
      if (!std::isfinite(in[c])) {
        o[c] = 0;  // no surface
        continue;
      }
      const double mm = std::round(static_cast<double>(in[c]) * 1000.0);
      o[c] = static_cast<uint16_t>(std::clamp(mm, 1.0, 65535.0));  // 0 is "no surface"
    }
  }
  return out;
}

cv::Mat IdsRgba(const cv::Mat& ids) {
  cv::Mat out(ids.size(), CV_8UC4, cv::Scalar::all(0));
  for (int r = 0; r < ids.rows; ++r) {
    const int* in = ids.ptr<int>(r);
    cv::Vec4b* o = out.ptr<cv::Vec4b>(r);
    for (int c = 0; c < ids.cols; ++c) {
      if (in[c] < 0) continue;
      const uint32_t v = static_cast<uint32_t>(in[c]) + 1;
      // Written as BGRA: B holds the high byte so the file's R is the low byte.
      o[c] = cv::Vec4b(static_cast<uchar>(v >> 16), static_cast<uchar>(v >> 8),
                       static_cast<uchar>(v), 255);
    }
  }
  return out;
}

struct Job {
  const PosedImage* pose;
  int camera_id;
  std::string relative;  // output path relative to DIR, without ".png"
};

// The images written besides the colour one, and how layers are shown.
struct RenderOutputs {
  bool depth = false;       // DIR/NAME.depth.png
  bool ids = false;         // DIR/NAME.ids.png
  bool view_layers = true;  // false: the base-colour texture only
};

// The renderer's options from the command line; "" or what is wrong with them.
std::string ParseRenderOptions(const Args& parsed, RenderOptions* options) {
  std::string error;
  if (parsed.Has("--supersample")) {
    if (!ParseInt(parsed.Get("--supersample"), "--supersample", &options->raster.supersample,
                  &error))
      return error;
    if (options->raster.supersample < 1 || options->raster.supersample > 4)
      return "--supersample: must be 1..4";
  }
  if (parsed.Has("--filter")) {
    const std::string filter = parsed.Get("--filter");
    if (filter == "bilinear") {
      options->filter = TextureFilter::kBilinear;
    } else if (filter == "nearest") {
      options->filter = TextureFilter::kNearest;
    } else {
      return "--filter: '" + filter + "' is not nearest|bilinear";
    }
  }
  if (parsed.Has("--near")) {
    if (!ParseDouble(parsed.Get("--near"), "--near", &options->raster.near_m, &error)) return error;
    if (!(options->raster.near_m > 0)) return "--near: must be > 0";
  }
  options->raster.cull_back_faces = parsed.Switch("--cull-back-faces");
  return "";
}

// The cameras, each valid and small enough to render with n x n samples per pixel.
Status ReadRenderCameras(const std::string& camera_path, int n, std::map<int, Camera>* cameras) {
  FRESCO_RETURN_IF_ERROR(ReadCameras(camera_path, cameras));
  if (cameras->empty()) return Status::Error(camera_path + ": no camera");
  for (const auto& [id, camera] : *cameras) {
    FRESCO_RETURN_IF_ERROR(camera.Validate(camera_path + ": camera " + std::to_string(id)));
    if (static_cast<double>(camera.width) * camera.height * n * n > kMaxSamplesPerImage) {
      return Status::Error(camera_path + ": camera " + std::to_string(id) + ": image size " +
                           std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                           " x " + std::to_string(n * n) +
                           " samples per pixel is too large (at most " + std::to_string(1 << 26) +
                           " samples)");
    }
  }
  return Status::Ok();
}

// Where the poses come from, and the cameras they may use.
struct PoseSource {
  const std::string& poses_path;
  const std::string& camera_path;
  const std::map<int, Camera>& cameras;
  bool is_tum = false;
};

// Pose i as messages name it.
std::string PoseWhat(const PoseSource& source, const std::vector<PosedImage>& poses, size_t i) {
  return source.poses_path + ": " +
         (source.is_tum ? "pose " + std::to_string(i + 1) : "image '" + poses[i].name + "'");
}

// Pose i's job: its camera (its own, or the only one) and its output name.
Status JobFor(const PoseSource& source, const std::vector<PosedImage>& poses, size_t i, Job* job) {
  const PosedImage& pose = poses[i];
  const std::string what = PoseWhat(source, poses, i);
  if (!pose.cam_from_world.AllFinite()) return Status::Error(what + ": pose is not finite");
  job->pose = &pose;
  if (source.cameras.count(pose.camera_id)) {
    job->camera_id = pose.camera_id;
  } else if (source.cameras.size() == 1) {
    job->camera_id = source.cameras.begin()->first;
  } else {
    return Status::Error(what + ": CAMERA_ID " + std::to_string(pose.camera_id) + " is not in " +
                         source.camera_path);
  }
  if (source.is_tum) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu", i);
    job->relative = name;
  } else {
    std::string why;
    if (!OutputName(pose.name, "", &job->relative, &why)) return Status::Error(what + ": " + why);
  }
  return Status::Ok();
}

// Poses, each matched to its camera and output name; no two outputs the same file.
Status PlanJobs(const PoseSource& source, const std::vector<PosedImage>& poses,
                const RenderOutputs& outputs_asked, std::vector<Job>* jobs) {
  std::set<std::string> outputs;
  for (size_t i = 0; i < poses.size(); ++i) {
    Job job;
    FRESCO_RETURN_IF_ERROR(JobFor(source, poses, i, &job));
    if (!outputs.insert(job.relative).second) {
      return Status::Error(PoseWhat(source, poses, i) + ": output " + job.relative +
                           ".png would overwrite another image's");
    }
    jobs->push_back(job);
  }
  if (!outputs_asked.depth && !outputs_asked.ids) return Status::Ok();
  for (const Job& job : *jobs) {
    for (const char* suffix : {".depth", ".ids"}) {
      if (outputs.count(job.relative + suffix)) {
        return Status::Error(source.poses_path + ": output " + job.relative + suffix +
                             ".png clashes with an image's output");
      }
    }
  }
  return Status::Ok();
}

// Renders one job and writes its images under `out_dir`.
Status RenderJob(const Renderer& renderer, const Scene& scene, const Job& job,
                 const RenderOutputs& outputs, const std::string& out_dir) {
  RenderOutput out;
  if (outputs.view_layers)
    RenderViewDependent(renderer, scene, job.pose->cam_from_world, &out);
  else
    renderer.Render(scene, job.pose->cam_from_world, &out);
  const std::string base = (fs::path(out_dir) / job.relative).string();
  cv::Mat bgra;
  cv::cvtColor(out.rgba, bgra, cv::COLOR_RGBA2BGRA);
  Status written = WritePng(base + ".png", bgra);
  if (written.ok() && outputs.depth)
    written = WritePng(base + ".depth.png", DepthMillimetres(out.depth));
  if (written.ok() && outputs.ids) written = WritePng(base + ".ids.png", IdsRgba(out.triangle_id));
  return written;
}

}  // namespace

int RunVerbRender(const CommandArgs& args) {
  ArgSpec spec;
  spec.usage = "fresco render MODEL --camera CAMERA --poses POSES --out DIR [options]";
  spec.help = kHelp;
  spec.min_positional = 1;
  spec.max_positional = 1;
  spec.options = {"--camera", "--poses", "--out", "--supersample", "--filter", "--near"};
  spec.switches = {"--depth", "--ids", "--cull-back-faces", "--single-texture", "--quiet"};
  spec.required = {"--camera", "--poses", "--out"};
  Args parsed;
  int code = ParseVerbArgs("render", args, spec, &parsed);
  if (code >= 0) return code;

  const std::string model_path = parsed.positional[0];
  const std::string camera_path = parsed.Get("--camera");
  const std::string poses_path = parsed.Get("--poses");
  const std::string out_dir = parsed.Get("--out");
  if (out_dir.empty()) return UsageError("render", spec, "--out: empty folder name");

  RenderOptions options;
  if (const std::string error = ParseRenderOptions(parsed, &options); !error.empty())
    return UsageError("render", spec, error);
  RenderOutputs outputs;
  outputs.depth = parsed.Switch("--depth");
  outputs.ids = parsed.Switch("--ids");
  outputs.view_layers = !parsed.Switch("--single-texture");

  std::map<int, Camera> cameras;
  if (Status s = ReadRenderCameras(camera_path, options.raster.supersample, &cameras); !s.ok())
    return Fail(s);
  std::vector<PosedImage> poses;
  PoseSource source{poses_path, camera_path, cameras};
  if (Status s = ReadPoses(poses_path, &poses, &source.is_tum); !s.ok()) return Fail(s);
  if (poses.empty()) return Fail(Status::Error(poses_path + ": no poses"));
  std::vector<Job> jobs;
  if (Status s = PlanJobs(source, poses, outputs, &jobs); !s.ok()) return Fail(s);
  Scene scene;
  if (Status s = LoadScene(model_path, SceneLoadOptions(), &scene); !s.ok()) return Fail(s);
  if (Status s = MakeDirectories(out_dir); !s.ok()) return Fail(s);

  std::map<int, std::unique_ptr<Renderer>> renderers;  // by camera id (ray tables)
  Progress progress("render", static_cast<int>(jobs.size()), parsed.Switch("--quiet"));
  for (size_t i = 0; i < jobs.size(); ++i) {
    const Job& job = jobs[i];
    std::unique_ptr<Renderer>& renderer = renderers[job.camera_id];
    if (!renderer) renderer = std::make_unique<Renderer>(cameras.at(job.camera_id), options);
    if (Status written = RenderJob(*renderer, scene, job, outputs, out_dir); !written.ok())
      return Fail(written);
    progress.Update(static_cast<int>(i + 1), job.relative + ".png");
  }
  progress.Finish(std::to_string(jobs.size()) + " images in " + out_dir);
  return kExitOk;
}

}  // namespace fresco
