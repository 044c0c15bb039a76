#include "pipeline/synth/synth_writer.h"

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/cameramodel_io.h"
#include "pipeline/core/png_encode.h"
#include "pipeline/core/poses.h"
#include "pipeline/core/project.h"
#include "pipeline/synth/synth_spec.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

// Bumped whenever the renderer of synthetic frames changes what it writes.
constexpr const char* kSynthFormat = "fresco-synth-2";  // 2: frames as fast-decoding PNG

class Fnv64 {
 public:
  void Add(const void* data, size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < bytes; ++i) hash_ = (hash_ ^ p[i]) * 0x100000001b3ull;
  }
  template <typename T>
  void AddValue(const T& value) {
    Add(&value, sizeof(T));
  }
  void AddString(const std::string& s) {
    AddValue(s.size());
    Add(s.data(), s.size());
  }
  std::string Hex() const {
    char text[17];
    std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(hash_));
    return text;
  }

 private:
  uint64_t hash_ = 0xcbf29ce484222325ull;
};

// The COLMAP model that holds the same lens (COLMAP has no LENSMODEL_* names).
Camera ColmapCamera(const Camera& camera) {
  Camera c = camera;
  switch (camera.model) {
    case LensModel::kPinhole:
      c.model = LensModel::kColmapPinhole;
      break;
    case LensModel::kOpenCV4:
      c.model = LensModel::kColmapOpenCV;
      break;
    default:
      c.model = LensModel::kFullOpenCV;
      break;
  }
  return c;
}

Status WriteMoversJson(const std::string& path, const SynthCapture& plan) {
  json movers = json::array();
  for (const MoverOptions& m : plan.movers) {
    json centres = json::array();
    for (size_t f = 0; f < plan.true_poses.size(); ++f) {
      const Eigen::Vector3d c = MoverCentreAt(m, static_cast<int>(f));
      centres.push_back({c.x(), c.y(), c.z()});
    }
    movers.push_back({{"shape", MoverShapeName(m.shape)},
                      {"radius_m", m.radius_m},
                      {"rgb", {m.rgb[0], m.rgb[1], m.rgb[2]}},
                      {"start", {m.start.x(), m.start.y(), m.start.z()}},
                      {"end", {m.end.x(), m.end.y(), m.end.z()}},
                      {"period_frames", m.period_frames},
                      {"phase", m.phase},
                      {"spin_deg_per_frame", m.spin_deg_per_frame},
                      {"centre_per_frame", centres}});
  }
  return WriteFileAtomic(path, json({{"movers", movers}}).dump(1) + "\n");
}

// The fingerprint of a planned capture: settings, scene, the plan (so that changes to the
// path, noise or mover code count) and the pixels of frame 0 (changes to the renderer).
std::string PlanFingerprint(const Scene& scene, const SynthOptions& options,
                            const SynthCapture& plan) {
  Fnv64 h;
  h.AddString(kSynthFormat);
  SynthOptions o = options;
  o.threads = 0;  // does not change the output
  h.AddString(SynthOptionsToJson(o));
  const TriangleMesh& mesh = scene.mesh;
  h.AddValue(scene.origin_in_world);
  for (const Eigen::Vector3d& v : mesh.vertices) h.AddValue(v);
  for (const Eigen::Vector3i& t : mesh.triangles) h.AddValue(t);
  for (const auto& uv : mesh.uvs) {
    for (const Eigen::Vector2f& c : uv) h.AddValue(c);
  }
  for (int m : mesh.material) h.AddValue(m);
  for (const Material& m : scene.materials) {
    h.AddValue(m.base_color_factor);
    h.AddValue(m.base_color_texture);
  }
  for (const Texture& t : scene.textures) {
    h.AddValue(t.wrap_s);
    h.AddValue(t.wrap_t);
    h.AddValue(t.rgba.rows);
    h.AddValue(t.rgba.cols);
    h.AddValue(t.rgba.type());
    for (int y = 0; y < t.rgba.rows; ++y) h.Add(t.rgba.ptr(y), t.rgba.cols * t.rgba.elemSize());
  }
  for (double p : plan.camera.Params()) h.AddValue(p);
  for (size_t i = 0; i < plan.true_poses.size(); ++i) {
    for (const PosedImage* image : {&plan.true_poses[i], &plan.given_poses[i]}) {
      h.AddString(image->name);
      h.AddValue(image->cam_from_world.rotation.coeffs().eval());
      h.AddValue(image->cam_from_world.translation);
    }
    h.AddValue(plan.exposure_gains[i]);
  }
  for (const MoverOptions& m : plan.movers) {
    h.AddValue(m.shape);
    h.AddValue(m.radius_m);
    h.AddValue(m.rgb);
    h.AddValue(m.start);
    h.AddValue(m.end);
    h.AddValue(m.period_frames);
    h.AddValue(m.phase);
    h.AddValue(m.spin_deg_per_frame);
  }
  if (!plan.true_poses.empty()) {
    SynthCapture first = plan;
    first.true_poses.resize(1);
    first.given_poses.resize(1);
    first.exposure_gains.resize(1);
    SynthOptions one = options;
    one.threads = 1;
    RenderSynthFrames(scene, one, first, [&](int, const cv::Mat& bgr) {
      for (int y = 0; y < bgr.rows; ++y) h.Add(bgr.ptr(y), bgr.cols * bgr.elemSize());
      return Status::Ok();
    });
  }
  return h.Hex();
}

// Renders a planned stream's frames into a staging folder for ROOT/frames (`frames_dir`,
// committed by the caller). `done` counts the frames written over all streams, of `total`.
Status RenderFramesStaged(const Scene& scene, const SynthOptions& options, const SynthCapture& plan,
                          const fs::path& root, const std::string& dir,
                          const SynthWriteOptions& write_options, int total, int* done,
                          StagedFolder* frames_dir) {
  FRESCO_RETURN_IF_ERROR(frames_dir->Open((root / "frames").string()));
  return RenderSynthFrames(scene, options, plan, [&](int index, const cv::Mat& bgr) -> Status {
    if (write_options.stop && write_options.stop()) {
      return Status::Failed(dir + ": stopped after " + std::to_string(*done) + " of " +
                            std::to_string(total) + " frames");
    }
    std::vector<uint8_t> png;
    const std::string name = plan.true_poses[index].name;
    const std::string path = (fs::path(frames_dir->path()) / name).string();
    if (Status s = EncodeFastDecodingPng(bgr, &png); !s.ok())
      return s.WithMessage((root / "frames" / name).string() + ": " + s.message());
    FRESCO_RETURN_IF_ERROR(WriteFileAtomic(path, std::string(png.begin(), png.end())));
    ++*done;
    if (write_options.progress) write_options.progress(*done, total);
    return Status::Ok();
  });
}

// A stream's camera, given and true poses, exposure gains and movers, under ROOT.
Status WriteStreamFiles(const SynthCapture& plan, const fs::path& root) {
  CameraModelFile model_file;
  model_file.camera = plan.camera;
  FRESCO_RETURN_IF_ERROR(WriteCameraModel((root / "camera.cameramodel").string(), model_file));
  ColmapModel given;
  given.cameras[1] = ColmapCamera(plan.camera);
  given.images = plan.given_poses;
  FRESCO_RETURN_IF_ERROR(WriteColmapModel((root / "sparse").string(), given));
  ColmapModel truth = given;
  truth.images = plan.true_poses;
  FRESCO_RETURN_IF_ERROR(WriteColmapModel((root / "truth").string(), truth));
  std::ostringstream exposure;
  exposure << "# NAME GAIN: the exposure gain applied to each rendered frame\n";
  exposure.precision(9);
  for (size_t i = 0; i < plan.true_poses.size(); ++i) {
    exposure << plan.true_poses[i].name << " " << plan.exposure_gains[i] << "\n";
  }
  FRESCO_RETURN_IF_ERROR(
      WriteFileAtomic((root / "truth" / "exposure.txt").string(), exposure.str()));
  return WriteMoversJson((root / "truth" / "movers.json").string(), plan);
}

// True when DIR holds a complete capture whose stamp is `stamp`.
bool CaptureIsCurrent(const fs::path& root, const std::string& stamp) {
  std::string existing;
  return fs::is_regular_file(root / "project.json") &&
         fs::is_regular_file(root / "synth_stamp.txt") &&
         ReadFileToString((root / "synth_stamp.txt").string(), &existing).ok() && existing == stamp;
}

// The folder's last files: scene, synth.json (`settings` plus scene and fingerprint), the
// stamp, and the project.
Status FinishCaptureFolder(const Scene& scene, const fs::path& root, json settings,
                           const SynthWriteOptions& write_options, const std::string& fingerprint,
                           Project project) {
  FRESCO_RETURN_IF_ERROR(SaveGltfScene(scene, (root / "scene.gltf").string()));
  settings["scene"] =
      write_options.scene_source.empty() ? "scene.gltf" : write_options.scene_source;
  settings["fingerprint"] = fingerprint;
  FRESCO_RETURN_IF_ERROR(WriteFileAtomic((root / "synth.json").string(), settings.dump(2) + "\n"));
  FRESCO_RETURN_IF_ERROR(WriteFileAtomic((root / "synth_stamp.txt").string(), fingerprint + "\n"));
  const std::string project_path = (root / "project.json").string();
  project.scene = "scene.gltf";
  // The pipeline's settings are the defaults: left out, so the capture paints with the
  // defaults of the Fresco that reads it (written out, they would pin this version's).
  json written = json::parse(ProjectToJsonText(project));
  written.erase("pipeline");
  return WriteFileAtomic(project_path, written.dump(2) + "\n");
}

// From here on the folder is rewritten: without project.json (and the stamp) it is
// incomplete, so a crash is never taken for a finished capture.
void MarkIncomplete(const fs::path& root) {
  std::error_code ec;
  fs::remove(root / "project.json", ec);
  fs::remove(root / "synth_stamp.txt", ec);
}

}  // namespace

std::string SynthFingerprint(const Scene& scene, const SynthOptions& options) {
  SynthCapture plan;
  if (!PlanSynthCapture(scene, options, &plan).ok()) return "";
  return PlanFingerprint(scene, options, plan);
}

Status WriteSynthCapture(const Scene& scene, const SynthOptions& options, const std::string& dir,
                         const SynthWriteOptions& write_options, SynthWriteResult* result) {
  SynthWriteResult local;
  if (!result) result = &local;
  *result = SynthWriteResult();
  SynthCapture plan;
  // The options were checked when the job was built: a plan that fails now is failed work.
  FRESCO_RETURN_IF_ERROR(PlanSynthCapture(scene, options, &plan).Reclassified(StatusKind::kFailed));
  const int frames = static_cast<int>(plan.true_poses.size());
  result->frames = frames;
  result->fingerprint = PlanFingerprint(scene, options, plan);

  const fs::path root(dir);
  if (write_options.skip_if_current && CaptureIsCurrent(root, result->fingerprint + "\n")) {
    result->skipped = true;
    return Status::Ok();
  }
  for (const char* sub : {"sparse", "truth"}) {
    FRESCO_RETURN_IF_ERROR(MakeDirectories((root / sub).string()));
  }
  // Frames, streamed into a staging folder: the earlier capture stays complete until every
  // frame is written.
  StagedFolder frames_dir;
  int done = 0;
  FRESCO_RETURN_IF_ERROR(RenderFramesStaged(scene, options, plan, root, dir, write_options, frames,
                                            &done, &frames_dir));
  MarkIncomplete(root);
  FRESCO_RETURN_IF_ERROR(frames_dir.Commit());
  FRESCO_RETURN_IF_ERROR(WriteStreamFiles(plan, root));
  Project project;
  project.fresco_version = 1;
  project.camera = "camera.cameramodel";
  project.video = "frames/";
  project.poses = "sparse/images.txt";
  project.truth.poses = "truth/images.txt";
  return FinishCaptureFolder(scene, root, json::parse(SynthOptionsToJson(options)), write_options,
                             result->fingerprint, project);
}

Status PlanSynthStreams(const Scene& scene, const std::vector<SynthStream>& streams,
                        std::vector<SynthStream>* resolved, std::vector<SynthCapture>* plans) {
  *resolved = streams;
  plans->assign(streams.size(), SynthCapture());
  for (size_t k = 0; k < streams.size(); ++k) {
    SynthOptions& o = (*resolved)[k].options;
    if (k > 0) {  // the movers the first stream placed, for every stream, on one clock
      o.movers = (*plans)[0].movers;
      o.random_movers = 0;
      if (streams[k].fps > 0 && streams[0].fps > 0) {
        const double frames_per_first_frame = streams[k].fps / streams[0].fps;
        for (MoverOptions& m : o.movers) {
          m.period_frames *= frames_per_first_frame;
          m.spin_deg_per_frame /= frames_per_first_frame;
        }
      }
    }
    if (Status s = PlanSynthCapture(scene, o, &(*plans)[k]); !s.ok())
      return s.WithMessage("streams[" + std::to_string(k) + "]." + s.message());
  }
  return Status::Ok();
}

Status WriteSynthStreams(const Scene& scene, const std::vector<SynthStream>& streams,
                         const std::string& dir, const SynthWriteOptions& write_options,
                         SynthWriteResult* result) {
  SynthWriteResult local;
  if (!result) result = &local;
  *result = SynthWriteResult();
  if (streams.empty()) return Status::Internal(dir + ": no streams to write");
  std::vector<SynthStream> resolved;
  std::vector<SynthCapture> plans;
  FRESCO_RETURN_IF_ERROR(  // as in WriteSynthCapture: failed work, not bad input
      PlanSynthStreams(scene, streams, &resolved, &plans).Reclassified(StatusKind::kFailed));
  Fnv64 h;
  h.AddString("streams");
  for (size_t k = 0; k < resolved.size(); ++k) {
    h.AddString(resolved[k].name);
    h.AddValue(resolved[k].time_offset_s);
    h.AddValue(resolved[k].fps);
    h.AddString(PlanFingerprint(scene, resolved[k].options, plans[k]));
    result->frames += static_cast<int>(plans[k].true_poses.size());
  }
  result->fingerprint = h.Hex();
  const fs::path root(dir);
  if (write_options.skip_if_current && CaptureIsCurrent(root, result->fingerprint + "\n")) {
    result->skipped = true;
    return Status::Ok();
  }
  // Every stream's frames first, so that a stop keeps the earlier capture whole.
  std::vector<std::unique_ptr<StagedFolder>> frames_dirs;
  int done = 0;
  for (size_t k = 0; k < resolved.size(); ++k) {
    const fs::path stream_root = root / resolved[k].name;
    for (const char* sub : {"sparse", "truth"}) {
      FRESCO_RETURN_IF_ERROR(MakeDirectories((stream_root / sub).string()));
    }
    frames_dirs.push_back(std::make_unique<StagedFolder>());
    FRESCO_RETURN_IF_ERROR(RenderFramesStaged(scene, resolved[k].options, plans[k], stream_root,
                                              dir, write_options, result->frames, &done,
                                              frames_dirs.back().get()));
  }
  MarkIncomplete(root);
  Project project;
  project.fresco_version = 2;
  json settings = {{"streams", json::array()}};
  for (size_t k = 0; k < resolved.size(); ++k) {
    const std::string& name = resolved[k].name;
    FRESCO_RETURN_IF_ERROR(frames_dirs[k]->Commit());
    FRESCO_RETURN_IF_ERROR(WriteStreamFiles(plans[k], root / name));
    project.streams.push_back({name + "/camera.cameramodel", name + "/frames/",
                               name + "/sparse/images.txt", resolved[k].time_offset_s,
                               resolved[k].fps});
    json stream = json::parse(SynthOptionsToJson(resolved[k].options));
    stream["name"] = name;
    stream["time_offset_s"] = resolved[k].time_offset_s;
    if (resolved[k].fps > 0) stream["fps"] = resolved[k].fps;
    settings["streams"].push_back(stream);
  }
  return FinishCaptureFolder(scene, root, settings, write_options, result->fingerprint, project);
}

Status ExportSynthScene(const Scene& scene, const std::vector<std::string>& texture_files,
                        const std::string& gltf_path) {
  const fs::path parent = fs::absolute(gltf_path).parent_path();
  FRESCO_RETURN_IF_ERROR(MakeDirectories(parent.string()));
  FRESCO_RETURN_IF_ERROR(SaveGltfScene(scene, gltf_path));
  bool any = false;
  for (const std::string& f : texture_files) any = any || !f.empty();
  if (!any) return Status::Ok();

  std::string text;
  FRESCO_RETURN_IF_ERROR(ReadFileToString(gltf_path, &text).Reclassified(StatusKind::kOutput));
  json gltf = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (gltf.is_discarded() || !gltf.contains("textures") || !gltf.contains("images")) {
    return Status::Internal(gltf_path + ": written glTF has no textures/images to point at files");
  }
  json& textures = gltf["textures"];
  json& images = gltf["images"];
  if (textures.size() != scene.textures.size()) {
    return Status::Internal(gltf_path + ": written glTF has " + std::to_string(textures.size()) +
                            " textures for the scene's " + std::to_string(scene.textures.size()));
  }
  std::set<std::string> replaced;
  for (size_t i = 0; i < texture_files.size() && i < textures.size(); ++i) {
    if (texture_files[i].empty() || !textures[i].contains("source")) continue;
    const int source = textures[i]["source"].get<int>();
    if (source < 0 || source >= static_cast<int>(images.size())) continue;
    json& image = images[source];
    if (image.contains("uri")) replaced.insert(image["uri"].get<std::string>());
    const fs::path file = fs::absolute(texture_files[i]).lexically_normal();
    image["uri"] = file.lexically_relative(parent).generic_string();
    std::string ext = file.extension().string();
    for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    image["mimeType"] = (ext == ".jpg" || ext == ".jpeg") ? "image/jpeg" : "image/png";
    image.erase("bufferView");
  }
  FRESCO_RETURN_IF_ERROR(WriteFileAtomic(gltf_path, gltf.dump(2) + "\n"));
  // Remove the PNG copies nothing refers to any more.
  std::set<std::string> still_used;
  for (const json& image : images) {
    if (image.contains("uri")) still_used.insert(image["uri"].get<std::string>());
  }
  std::error_code ec;
  for (const std::string& uri : replaced) {
    if (!still_used.count(uri) && uri.find("..") == std::string::npos &&
        uri.find(':') == std::string::npos) {
      fs::remove(parent / uri, ec);
    }
  }
  return Status::Ok();
}

}  // namespace fresco
