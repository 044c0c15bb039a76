#include "pipeline/synth/synth_spec.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/image_io.h"
#include "pipeline/synth/blocks_scene.h"
#include "pipeline/synth/mesh_refine.h"
#include "pipeline/synth/procedural_scenes.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

// Reads one JSON object strictly: every key must be read (Finish reports the first unknown
// one), types are checked, and messages name the file and the field's JSON path.
class ObjectReader {
 public:
  ObjectReader(const json& object, std::string path, std::string file)
      : object_(object), path_(std::move(path)), file_(std::move(file)) {}

  Status Error(const std::string& key, const std::string& what) const {
    return Status::Error(file_ + ": " + Field(key) + ": " + what);
  }
  std::string Field(const std::string& key) const {
    return path_.empty() ? key : path_ + "." + key;
  }
  bool Has(const std::string& key) const { return object_.contains(key); }
  const json* Get(const std::string& key) {
    seen_.insert(key);
    auto it = object_.find(key);
    return it == object_.end() ? nullptr : &*it;
  }

  Status Number(const std::string& key, double* value) {
    const json* v = Get(key);
    if (!v) return Status::Ok();
    if (!v->is_number()) return Error(key, "must be a number");
    *value = v->get<double>();
    if (!std::isfinite(*value)) return Error(key, "must be finite");
    return Status::Ok();
  }
  Status Int(const std::string& key, int* value) {
    const json* v = Get(key);
    if (!v) return Status::Ok();
    if (!v->is_number_integer()) return Error(key, "must be an integer");
    const long long x = v->get<long long>();
    if (x < -2147483647LL || x > 2147483647LL) return Error(key, "out of range");
    *value = static_cast<int>(x);
    return Status::Ok();
  }
  Status Unsigned(const std::string& key, unsigned* value) {
    const json* v = Get(key);
    if (!v) return Status::Ok();
    if (!v->is_number_integer() || v->get<long long>() < 0 || v->get<long long>() > 4294967295LL) {
      return Error(key, "must be an integer in [0, 4294967295]");
    }
    *value = static_cast<unsigned>(v->get<long long>());
    return Status::Ok();
  }
  Status Bool(const std::string& key, bool* value) {
    const json* v = Get(key);
    if (!v) return Status::Ok();
    if (!v->is_boolean()) return Error(key, "must be true or false");
    *value = v->get<bool>();
    return Status::Ok();
  }
  Status String(const std::string& key, std::string* value) {
    const json* v = Get(key);
    if (!v) return Status::Ok();
    if (!v->is_string()) return Error(key, "must be a string");
    *value = v->get<std::string>();
    return Status::Ok();
  }
  template <int N>
  Status Vector(const std::string& key, Eigen::Matrix<double, N, 1>* value) {
    const json* v = Get(key);
    if (!v) return Status::Ok();
    if (!v->is_array() || v->size() != N) {
      return Error(key, "must be an array of " + std::to_string(N) + " numbers");
    }
    for (int i = 0; i < N; ++i) {
      if (!(*v)[i].is_number()) return Error(key, "must be an array of numbers");
      (*value)[i] = (*v)[i].get<double>();
      if (!std::isfinite((*value)[i])) return Error(key, "must be finite");
    }
    return Status::Ok();
  }
  Status Rgb(const std::string& key, cv::Vec3b* value) {
    const json* v = Get(key);
    if (!v) return Status::Ok();
    if (!v->is_array() || v->size() != 3) return Error(key, "must be [r, g, b] (0..255)");
    for (int i = 0; i < 3; ++i) {
      if (!(*v)[i].is_number_integer() || (*v)[i].get<int>() < 0 || (*v)[i].get<int>() > 255) {
        return Error(key, "must be [r, g, b] with integers in 0..255");
      }
      (*value)[i] = static_cast<uchar>((*v)[i].get<int>());
    }
    return Status::Ok();
  }
  Status Finish() const {
    for (auto it = object_.begin(); it != object_.end(); ++it) {
      if (!seen_.count(it.key())) return Error(it.key(), "unknown key");
    }
    return Status::Ok();
  }
  const std::string& file() const { return file_; }

 private:
  const json& object_;
  std::string path_, file_;
  std::set<std::string> seen_;
};

std::string Resolve(const std::string& base_dir, const std::string& path) {
  if (path.empty()) return path;
  fs::path p(path);
  if (p.is_absolute()) return p.lexically_normal().string();
  return (fs::path(base_dir) / p).lexically_normal().string();
}

// What the scene is, for scene-dependent defaults.
enum class SceneKind { kRoom, kStreet, kPlane, kObject, kBlocks };
struct SceneInfo {
  SceneKind kind = SceneKind::kObject;
  Eigen::Vector3d room_size = Eigen::Vector3d::Zero();
  StreetOptions street;
  BlocksOptions blocks;
  double plane_w = 0, plane_h = 0;
  Eigen::Vector3d bounds_min = Eigen::Vector3d::Zero(), bounds_max = Eigen::Vector3d::Zero();
};

Status ReadImageFile(const std::string& path, const std::string& what, const ObjectReader& reader,
                     cv::Mat* image) {
  if (!fs::is_regular_file(path)) return reader.Error(what, "no such file: " + path);
  if (!ReadImage(path, image, cv::IMREAD_UNCHANGED).ok() || image->depth() != CV_8U) {
    return reader.Error(what, "cannot read an 8-bit image from " + path);
  }
  return Status::Ok();
}

// A scene file (glTF, PLY or OBJ) as the scene.
Status LoadSceneFile(const std::string& path, const ObjectReader& top, SynthJob* job,
                     SceneInfo* info) {
  if (!fs::is_regular_file(path)) return top.Error("scene", "no such file: " + path);
  FRESCO_RETURN_IF_ERROR(LoadScene(path, SceneLoadOptions(), &job->scene));
  job->scene_source = path;
  job->texture_files.assign(job->scene.textures.size(), "");
  info->kind = SceneKind::kObject;
  return Status::Ok();
}

// The cube room's textures (image files per face, `files`) and their repeats.
Status ReadCubeRoomTextures(ObjectReader* r, const std::string& base_dir, CubeRoomOptions* room,
                            std::array<std::string, kCubeRoomFaces>* files) {
  const std::string& file = r->file();
  if (const json* textures = r->Get("textures")) {
    if (!textures->is_object()) return r->Error("textures", "must be an object {face: file}");
    ObjectReader t(*textures, "scene.textures", file);
    for (int f = 0; f < kCubeRoomFaces; ++f) {
      std::string name;
      FRESCO_RETURN_IF_ERROR(t.String(CubeRoomFaceName(f), &name));
      if (name.empty()) continue;
      (*files)[f] = Resolve(base_dir, name);
      FRESCO_RETURN_IF_ERROR(ReadImageFile((*files)[f], CubeRoomFaceName(f), t, &room->images[f]));
      room->texture_names[f] = fs::path(name).stem().string();
    }
    FRESCO_RETURN_IF_ERROR(t.Finish());
  }
  if (const json* repeat = r->Get("repeat")) {
    if (!repeat->is_object()) return r->Error("repeat", "must be an object {face: [u, v]}");
    ObjectReader t(*repeat, "scene.repeat", file);
    for (int f = 0; f < kCubeRoomFaces; ++f) {
      FRESCO_RETURN_IF_ERROR(t.Vector<2>(CubeRoomFaceName(f), &room->repeat[f]));
    }
    FRESCO_RETURN_IF_ERROR(t.Finish());
  }
  return Status::Ok();
}

Status BuildCubeRoom(ObjectReader* r, const std::string& base_dir, SynthJob* job, SceneInfo* info) {
  CubeRoomOptions room;
  FRESCO_RETURN_IF_ERROR(r->Vector<3>("size_m", &room.size_m));
  FRESCO_RETURN_IF_ERROR(r->Unsigned("seed", &room.seed));
  FRESCO_RETURN_IF_ERROR(r->Int("texture_px", &room.procedural_texture_px));
  std::array<std::string, kCubeRoomFaces> files;
  FRESCO_RETURN_IF_ERROR(ReadCubeRoomTextures(r, base_dir, &room, &files));
  FRESCO_RETURN_IF_ERROR(r->Finish());
  Status s = MakeCubeRoomScene(room, &job->scene);
  if (!s.ok()) return Status::Error(r->file() + ": scene: " + s.message());
  job->texture_files.assign(files.begin(), files.end());
  info->kind = SceneKind::kRoom;
  info->room_size = room.size_m;
  return Status::Ok();
}

Status BuildStreet(ObjectReader* r, SynthJob* job, SceneInfo* info) {
  StreetOptions street;
  FRESCO_RETURN_IF_ERROR(r->Number("length_m", &street.length_m));
  FRESCO_RETURN_IF_ERROR(r->Number("street_width_m", &street.street_width_m));
  FRESCO_RETURN_IF_ERROR(r->Int("buildings_per_side", &street.buildings_per_side));
  FRESCO_RETURN_IF_ERROR(r->Number("min_height_m", &street.min_height_m));
  FRESCO_RETURN_IF_ERROR(r->Number("max_height_m", &street.max_height_m));
  FRESCO_RETURN_IF_ERROR(r->Int("texture_px", &street.texture_px));
  FRESCO_RETURN_IF_ERROR(r->Unsigned("seed", &street.seed));
  FRESCO_RETURN_IF_ERROR(r->Finish());
  Status s = MakeStreetScene(street, &job->scene);
  if (!s.ok()) return Status::Error(r->file() + ": scene: " + s.message());
  job->texture_files.assign(job->scene.textures.size(), "");
  info->kind = SceneKind::kStreet;
  info->street = street;
  return Status::Ok();
}

// A textured plane (width x height) or cube (edge), its texture from an image file.
Status BuildPlaneOrCube(bool plane, ObjectReader* r, const std::string& base_dir, SynthJob* job,
                        SceneInfo* info) {
  double w = plane ? 2.0 : 1.0, h = 2.0;
  FRESCO_RETURN_IF_ERROR(r->Number(plane ? "width_m" : "edge_m", &w));
  if (plane) FRESCO_RETURN_IF_ERROR(r->Number("height_m", &h));
  if (!(w > 0) || !(h > 0)) return r->Error(plane ? "width_m" : "edge_m", "must be > 0");
  std::string texture_name;
  FRESCO_RETURN_IF_ERROR(r->String("texture", &texture_name));
  cv::Mat image;
  std::string texture_file;
  if (!texture_name.empty()) {
    texture_file = Resolve(base_dir, texture_name);
    FRESCO_RETURN_IF_ERROR(ReadImageFile(texture_file, "texture", *r, &image));
  }
  FRESCO_RETURN_IF_ERROR(r->Finish());
  job->scene = plane ? MakeTexturedPlaneScene(w, h, RgbaFromImage(image))
                     : MakeTexturedCubeScene(w, RgbaFromImage(image));
  job->texture_files.assign(job->scene.textures.size(), texture_file);
  info->kind = plane ? SceneKind::kPlane : SceneKind::kObject;
  info->plane_w = w;
  info->plane_h = h;
  return Status::Ok();
}

Status BuildBlocks(ObjectReader* r, SynthJob* job, SceneInfo* info) {
  BlocksOptions blocks;
  FRESCO_RETURN_IF_ERROR(r->Number("ground_m", &blocks.ground_m));
  FRESCO_RETURN_IF_ERROR(r->Int("blocks", &blocks.blocks));
  FRESCO_RETURN_IF_ERROR(r->Number("area_m", &blocks.area_m));
  FRESCO_RETURN_IF_ERROR(r->Number("min_size_m", &blocks.min_size_m));
  FRESCO_RETURN_IF_ERROR(r->Number("max_size_m", &blocks.max_size_m));
  FRESCO_RETURN_IF_ERROR(r->Number("max_height_m", &blocks.max_height_m));
  FRESCO_RETURN_IF_ERROR(r->Int("texels_per_m", &blocks.texels_per_m));
  FRESCO_RETURN_IF_ERROR(r->Unsigned("seed", &blocks.seed));
  FRESCO_RETURN_IF_ERROR(r->Finish());
  Status s = MakeBlocksScene(blocks, &job->scene);
  if (!s.ok()) return Status::Error(r->file() + ": scene: " + s.message());
  job->texture_files.assign(job->scene.textures.size(), "");
  info->kind = SceneKind::kBlocks;
  info->blocks = blocks;
  return Status::Ok();
}

Status BuildScene(const json& value, const std::string& file, const std::string& base_dir,
                  SynthJob* job, SceneInfo* info) {
  static const json kEmpty = json::object();
  ObjectReader top(kEmpty, "", file);
  std::string builtin;
  const json* object = nullptr;
  if (value.is_string()) {
    const std::string s = value.get<std::string>();
    if (s.rfind("builtin:", 0) != 0) return LoadSceneFile(Resolve(base_dir, s), top, job, info);
    builtin = s.substr(8);
  } else if (value.is_object()) {
    object = &value;
    if (!value.contains("builtin") || !value["builtin"].is_string()) {
      return top.Error("scene.builtin", "missing (a scene object names a built-in scene)");
    }
    builtin = value["builtin"].get<std::string>();
  } else {
    return top.Error("scene", "must be \"builtin:NAME\", a scene file path or an object");
  }
  ObjectReader r(object ? *object : kEmpty, "scene", file);
  std::string ignored;
  FRESCO_RETURN_IF_ERROR(r.String("builtin", &ignored));
  job->scene_source = "builtin:" + builtin;

  if (builtin == "cube-room") return BuildCubeRoom(&r, base_dir, job, info);
  if (builtin == "street") return BuildStreet(&r, job, info);
  if (builtin == "plane" || builtin == "cube")
    return BuildPlaneOrCube(builtin == "plane", &r, base_dir, job, info);
  if (builtin == "blocks") return BuildBlocks(&r, job, info);
  return r.Error("builtin", "unknown built-in scene '" + builtin +
                                "' (cube-room, street, plane, cube, blocks)");
}

// Path and mover-region defaults that fit the scene.
void SceneDefaults(const SceneInfo& info, CameraPathKind kind, SynthOptions* o) {
  CameraPathOptions p;
  p.kind = kind;
  const Eigen::Vector3d centre = 0.5 * (info.bounds_min + info.bounds_max);
  const double r = std::max(1e-3, 0.5 * (info.bounds_max - info.bounds_min).norm());
  switch (info.kind) {
    case SceneKind::kRoom: {
      const double w = info.room_size.x(), h = info.room_size.y(), d = info.room_size.z();
      const double m = std::min(w, d);
      p.target = Eigen::Vector3d(0, std::min(1.5, 0.5 * h), 0);
      p.height_m = p.target.y();
      p.radius_m = kind == CameraPathKind::kOrbit ? 0.2 * m : 0.1 * m;
      p.wander_m = 0.06 * m;
      p.look_at_target = false;
      p.pitch_deg = -5.0;
      p.tilt_deg = 40.0;
      p.wobble_deg = 4.0;
      p.walk_from = Eigen::Vector3d(-0.35 * w, p.target.y(), 0.1 * d);
      p.walk_to = Eigen::Vector3d(0.35 * w, p.target.y(), -0.1 * d);
      p.look_around_deg = 40.0;
      o->mover_region_min = Eigen::Vector3d(-0.45 * w, 0.0, -0.45 * d);
      o->mover_region_max = Eigen::Vector3d(0.45 * w, 0.6 * h, 0.45 * d);
      break;
    }
    case SceneKind::kStreet: {
      const double l = info.street.length_m, w = info.street.street_width_m;
      p.target = Eigen::Vector3d(0, 1.6, 0);
      p.height_m = 1.6;
      p.radius_m = kind == CameraPathKind::kOrbit ? 0.3 * w : 0.2 * w;
      p.wander_m = 0.05 * w;
      p.look_at_target = false;
      p.pitch_deg = 5.0;
      p.wobble_deg = 3.0;
      p.walk_from = Eigen::Vector3d(-0.35 * l, 1.6, -0.12 * w);
      p.walk_to = Eigen::Vector3d(0.35 * l, 1.6, 0.12 * w);
      p.look_around_deg = 35.0;
      o->mover_region_min = Eigen::Vector3d(-0.45 * l, 0.0, -(0.5 * w - 0.5));
      o->mover_region_max = Eigen::Vector3d(0.45 * l, 2.5, 0.5 * w - 0.5);
      break;
    }
    case SceneKind::kPlane: {
      const double s = std::max(info.plane_w, info.plane_h);
      p.target = Eigen::Vector3d::Zero();
      p.radius_m = 1.2 * s;
      p.start_deg = kind == CameraPathKind::kOrbit ? 45.0 : 90.0;
      p.turns = kind == CameraPathKind::kOrbit ? 0.25 : 0.0;
      p.wander_m = 0.1 * s;
      p.look_at_target = true;
      p.wobble_deg = 2.0;
      p.walk_from = Eigen::Vector3d(-0.4 * s, 0, 1.2 * s);
      p.walk_to = Eigen::Vector3d(0.4 * s, 0, 1.2 * s);
      p.look_around_deg = 0.0;
      o->mover_region_min = Eigen::Vector3d(-0.5 * info.plane_w, -0.5 * info.plane_h, 0.1 * s);
      o->mover_region_max = Eigen::Vector3d(0.5 * info.plane_w, 0.5 * info.plane_h, 0.5 * s);
      break;
    }
    case SceneKind::kBlocks: {
      // Around the cluster of boxes, looking at its middle from above: parallax everywhere.
      const double g = info.blocks.ground_m;
      p.target = Eigen::Vector3d(0, 0.3 * info.blocks.max_height_m, 0);
      p.radius_m = 0.6 * g;
      p.height_m = 0.5 * g;
      p.wander_m = 0.04 * g;
      p.look_at_target = true;
      p.wobble_deg = 2.0;
      p.walk_from = Eigen::Vector3d(-0.4 * g, 0.3 * g, 0.7 * g);
      p.walk_to = Eigen::Vector3d(0.4 * g, 0.3 * g, 0.7 * g);
      p.look_around_deg = 10.0;
      o->mover_region_min = Eigen::Vector3d(-0.4 * g, 0.0, -0.4 * g);
      o->mover_region_max = Eigen::Vector3d(0.4 * g, 0.3 * g, 0.4 * g);
      break;
    }
    case SceneKind::kObject: {
      p.target = centre;
      p.radius_m = 2.5 * r;
      p.height_m = centre.y() + (kind == CameraPathKind::kOrbit ? 0.8 : 0.6) * r;
      p.wander_m = 0.15 * r;
      p.look_at_target = true;
      p.wobble_deg = 3.0;
      p.walk_from = centre + Eigen::Vector3d(-2.0 * r, 0.3 * r, 2.5 * r);
      p.walk_to = centre + Eigen::Vector3d(2.0 * r, 0.3 * r, 2.5 * r);
      p.look_around_deg = 30.0;
      o->mover_region_min = centre - 1.8 * r * Eigen::Vector3d::Ones();
      o->mover_region_max = centre + 1.8 * r * Eigen::Vector3d::Ones();
      o->mover_region_min.y() = info.bounds_min.y();
      break;
    }
  }
  if (kind == CameraPathKind::kFixed) {  // a still camera looking at the target
    p.wobble_deg = 0.0;
    if (info.kind == SceneKind::kRoom) {  // up in a corner, as surveillance cameras are
      p.radius_m = 0.6 * std::min(info.room_size.x(), info.room_size.z());
      p.height_m = 0.85 * info.room_size.y();
      p.start_deg = 45.0;
    }
  }
  o->SetPathOptions(p);
}

// `field`: "path" or "streams[N].path", for messages.
Status ReadPath(const json& value, const std::string& file, const std::string& field,
                CameraPathOptions* p) {
  if (!value.is_object()) return Status::Error(file + ": " + field + ": must be an object");
  ObjectReader r(value, field, file);
  std::string kind;
  FRESCO_RETURN_IF_ERROR(r.String("kind", &kind));  // applied before (defaults depend on it)
  FRESCO_RETURN_IF_ERROR(r.Vector<3>("target", &p->target));
  FRESCO_RETURN_IF_ERROR(r.Number("radius_m", &p->radius_m));
  FRESCO_RETURN_IF_ERROR(r.Number("height_m", &p->height_m));
  FRESCO_RETURN_IF_ERROR(r.Number("turns", &p->turns));
  FRESCO_RETURN_IF_ERROR(r.Number("start_deg", &p->start_deg));
  FRESCO_RETURN_IF_ERROR(r.Number("wander_m", &p->wander_m));
  FRESCO_RETURN_IF_ERROR(r.Number("wobble_deg", &p->wobble_deg));
  FRESCO_RETURN_IF_ERROR(r.Bool("look_at_target", &p->look_at_target));
  FRESCO_RETURN_IF_ERROR(r.Number("pitch_deg", &p->pitch_deg));
  FRESCO_RETURN_IF_ERROR(r.Number("tilt_deg", &p->tilt_deg));
  FRESCO_RETURN_IF_ERROR(r.Vector<3>("walk_from", &p->walk_from));
  FRESCO_RETURN_IF_ERROR(r.Vector<3>("walk_to", &p->walk_to));
  FRESCO_RETURN_IF_ERROR(r.Number("look_around_deg", &p->look_around_deg));
  FRESCO_RETURN_IF_ERROR(r.Number("bob_m", &p->bob_m));
  // A fixed camera stands where the path's circle starts unless placed with `eye` (or, for
  // a stream's path without a kind, where the spec's path put it).
  const double start_rad = p->start_deg * M_PI / 180.0;
  if (value.contains("kind")) {
    p->eye = Eigen::Vector3d(p->target.x() + p->radius_m * std::cos(start_rad), p->height_m,
                             p->target.z() + p->radius_m * std::sin(start_rad));
  }
  FRESCO_RETURN_IF_ERROR(r.Vector<3>("eye", &p->eye));
  return r.Finish();
}

Status ReadMovers(const json& value, const std::string& file, std::vector<MoverOptions>* movers) {
  if (!value.is_array()) return Status::Error(file + ": movers: must be an array of objects");
  for (size_t i = 0; i < value.size(); ++i) {
    const std::string what = "movers[" + std::to_string(i) + "]";
    if (!value[i].is_object()) return Status::Error(file + ": " + what + ": must be an object");
    ObjectReader r(value[i], what, file);
    MoverOptions m;
    std::string shape = MoverShapeName(m.shape);
    FRESCO_RETURN_IF_ERROR(r.String("shape", &shape));
    if (!MoverShapeFromName(shape, &m.shape)) {
      return r.Error("shape", "unknown shape '" + shape + "' (sphere, box)");
    }
    FRESCO_RETURN_IF_ERROR(r.Number("radius_m", &m.radius_m));
    FRESCO_RETURN_IF_ERROR(r.Rgb("rgb", &m.rgb));
    FRESCO_RETURN_IF_ERROR(r.Vector<3>("start", &m.start));
    m.end = m.start;
    FRESCO_RETURN_IF_ERROR(r.Vector<3>("end", &m.end));
    FRESCO_RETURN_IF_ERROR(r.Number("period_frames", &m.period_frames));
    FRESCO_RETURN_IF_ERROR(r.Number("phase", &m.phase));
    FRESCO_RETURN_IF_ERROR(r.Number("spin_deg_per_frame", &m.spin_deg_per_frame));
    FRESCO_RETURN_IF_ERROR(r.Finish());
    movers->push_back(m);
  }
  return Status::Ok();
}

bool LensFromName(const std::string& name, LensModel* lens) {
  static const std::pair<const char*, LensModel> kNames[] = {{"pinhole", LensModel::kPinhole},
                                                             {"opencv4", LensModel::kOpenCV4},
                                                             {"opencv5", LensModel::kOpenCV5},
                                                             {"opencv8", LensModel::kOpenCV8}};
  for (const auto& [n, l] : kNames) {
    if (name == n) {
      *lens = l;
      return true;
    }
  }
  LensModel parsed;
  if (LensModelFromName(name, &parsed) &&
      (parsed == LensModel::kPinhole || parsed == LensModel::kOpenCV4 ||
       parsed == LensModel::kOpenCV5 || parsed == LensModel::kOpenCV8)) {
    *lens = parsed;
    return true;
  }
  return false;
}

std::string LensShortName(LensModel lens) {
  switch (lens) {
    case LensModel::kOpenCV4:
      return "opencv4";
    case LensModel::kOpenCV5:
      return "opencv5";
    case LensModel::kOpenCV8:
      return "opencv8";
    default:
      return "pinhole";
  }
}

Status ApplyOverride(const SynthSpecOverride& o, const std::string& file, json* spec) {
  json value;
  if (o.as_string) {
    value = o.value;
  } else {
    value = json::parse(o.value, nullptr, /*allow_exceptions=*/false);
    if (value.is_discarded()) value = o.value;
  }
  json* node = spec;
  std::stringstream keys(o.key);
  std::string key, path;
  std::vector<std::string> parts;
  while (std::getline(keys, key, '.')) parts.push_back(key);
  if (parts.empty()) return Status::Error(file + ": empty setting name");
  for (size_t i = 0; i < parts.size(); ++i) {
    json* child = nullptr;
    if (node->is_array()) {  // a list's entry by its index: streams.1.lens
      char* end = nullptr;
      const unsigned long index = std::strtoul(parts[i].c_str(), &end, 10);
      if (parts[i].empty() || *end != '\0' || index >= node->size()) {
        return Status::Error(file + ": " + path + ": has no entry '" + parts[i] + "' (0.." +
                             std::to_string(static_cast<long>(node->size()) - 1) + ")");
      }
      path += "[" + parts[i] + "]";
      child = &(*node)[index];
    } else {
      path += (path.empty() ? "" : ".") + parts[i];
      child = &(*node)[parts[i]];
    }
    if (i + 1 == parts.size()) {
      *child = value;
      break;
    }
    if (child->is_null()) *child = json::object();
    if (!child->is_object() && !child->is_array())
      return Status::Error(file + ": " + path + ": is not an object");
    node = child;
  }
  return Status::Ok();
}

// The path's kind from `object`'s "path" (default `kind`), the scene's defaults for it,
// then the path's other keys. The spec itself always takes the defaults; a stream (`r`
// names "streams[N]") only when its path names a kind, and keeps the spec's mover region.
Status ReadPathAndDefaults(const json& object, ObjectReader& r, const SceneInfo& info,
                           CameraPathKind kind, bool stream, SynthOptions* o) {
  const json* path = object.contains("path") ? &object["path"] : nullptr;
  const bool has_kind = path && path->is_object() && path->contains("kind");
  if (has_kind) {
    const json& k = (*path)["kind"];
    if (!k.is_string() || !CameraPathKindFromName(k.get<std::string>(), &kind)) {
      return r.Error("path.kind", "must be \"orbit\", \"walk\", \"handheld\" or \"fixed\"");
    }
  }
  if (!stream) {
    SceneDefaults(info, kind, o);
  } else if (has_kind) {
    const Eigen::Vector3d region_min = o->mover_region_min, region_max = o->mover_region_max;
    SceneDefaults(info, kind, o);
    o->mover_region_min = region_min;
    o->mover_region_max = region_max;
  }
  if (const json* p = r.Get("path")) {
    CameraPathOptions path_options = o->PathOptions();
    FRESCO_RETURN_IF_ERROR(ReadPath(*p, r.file(), r.Field("path"), &path_options));
    o->SetPathOptions(path_options);
  }
  return Status::Ok();
}

// The keys a spec and each of its streams may set: the camera, its frames and the noise.
Status ReadCameraKeys(ObjectReader& r, SynthOptions* o) {
  FRESCO_RETURN_IF_ERROR(r.Int("frames", &o->frames));
  if (const json* size = r.Get("size")) {
    bool ok = false;
    if (size->is_array() && size->size() == 2 && (*size)[0].is_number_integer() &&
        (*size)[1].is_number_integer()) {
      o->width = (*size)[0].get<int>();
      o->height = (*size)[1].get<int>();
      ok = true;
    } else if (size->is_string()) {
      const std::string s = size->get<std::string>();
      char x = 0, extra = 0;
      std::istringstream in(s);
      ok = static_cast<bool>(in >> o->width >> x >> o->height) && (x == 'x' || x == 'X') &&
           !(in >> extra);
    }
    if (!ok) return r.Error("size", "must be [width, height] or \"WIDTHxHEIGHT\"");
  }
  std::string lens;
  FRESCO_RETURN_IF_ERROR(r.String("lens", &lens));
  if (!lens.empty() && !LensFromName(lens, &o->lens)) {
    return r.Error("lens", "unknown lens '" + lens + "' (pinhole, opencv4, opencv5, opencv8)");
  }
  FRESCO_RETURN_IF_ERROR(r.Number("hfov_deg", &o->hfov_deg));
  FRESCO_RETURN_IF_ERROR(r.Number("pose_noise_deg", &o->pose_noise_deg));
  FRESCO_RETURN_IF_ERROR(r.Number("pose_noise_m", &o->pose_noise_m));
  FRESCO_RETURN_IF_ERROR(r.Number("exposure", &o->exposure_jitter));
  FRESCO_RETURN_IF_ERROR(r.Int("supersample", &o->supersample));
  return r.Unsigned("seed", &o->seed);
}

// A stream's folder name: letters, digits, '-', '_' and '.', not starting with '.'.
bool StreamNameOk(const std::string& name) {
  if (name.empty() || name.size() > 64 || name[0] == '.') return false;
  for (char c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.')
      return false;
  }
  return true;
}

// "streams": each entry starts from the spec's settings (job->options) and overrides its
// name, path, camera, frames, noise and time offset.
Status ReadStreams(const json& value, const std::string& file, const SceneInfo& info,
                   SynthJob* job) {
  if (!value.is_array() || value.empty())
    return Status::Error(file + ": streams: must be a non-empty array of objects");
  if (value.size() > 64) return Status::Error(file + ": streams: at most 64 streams");
  std::set<std::string> names;
  for (size_t i = 0; i < value.size(); ++i) {
    const std::string what = "streams[" + std::to_string(i) + "]";
    if (!value[i].is_object()) return Status::Error(file + ": " + what + ": must be an object");
    ObjectReader r(value[i], what, file);
    SynthStream stream;
    stream.name = "stream" + std::to_string(i);
    stream.options = job->options;
    FRESCO_RETURN_IF_ERROR(r.String("name", &stream.name));
    if (!StreamNameOk(stream.name)) {
      return r.Error("name",
                     "'" + stream.name + "' is not a folder name (letters, digits, '-', '_', '.')");
    }
    if (!names.insert(stream.name).second)
      return r.Error("name", "'" + stream.name + "' names two streams");
    FRESCO_RETURN_IF_ERROR(ReadPathAndDefaults(value[i], r, info, stream.options.path,
                                               /*stream=*/true, &stream.options));
    FRESCO_RETURN_IF_ERROR(ReadCameraKeys(r, &stream.options));
    FRESCO_RETURN_IF_ERROR(r.Number("time_offset_s", &stream.time_offset_s));
    FRESCO_RETURN_IF_ERROR(r.Number("fps", &stream.fps));
    if (r.Has("fps") && !(stream.fps > 0 && stream.fps <= 1000))
      return r.Error("fps", "must be in (0, 1000]");
    if (i > 0 && (stream.fps > 0) != (job->streams[0].fps > 0))
      return r.Error("fps", "give every stream's fps or none (streams[0] " +
                                std::string(job->streams[0].fps > 0 ? "has one)" : "has none)"));
    FRESCO_RETURN_IF_ERROR(r.Finish());
    if (Status check = stream.options.Check(); !check.ok())
      return Status::Error(file + ": " + what + "." + check.message());
    job->streams.push_back(stream);
  }
  return Status::Ok();
}

}  // namespace

Status BuildSynthJob(const SynthSpecInput& input, SynthJob* job) {
  *job = SynthJob();
  job->name = input.name;
  const std::string& file = input.name;
  json spec = json::parse(input.text, nullptr, /*allow_exceptions=*/false);
  if (spec.is_discarded()) return Status::Error(file + ": not valid JSON");
  if (!spec.is_object()) return Status::Error(file + ": must be a JSON object");
  for (const SynthSpecOverride& o : input.overrides) {
    FRESCO_RETURN_IF_ERROR(ApplyOverride(o, file, &spec));
  }
  ObjectReader r(spec, "", file);
  int version = 1;
  FRESCO_RETURN_IF_ERROR(r.Int("fresco_synth", &version));
  if (version != 1) return r.Error("fresco_synth", "unsupported version (1 expected)");

  // Scene first: the defaults depend on it.
  const json* scene = r.Get("scene");
  if (!scene)
    return r.Error("scene", "missing (e.g. \"builtin:cube-room\" or a glTF, PLY or OBJ file)");
  SceneInfo info;
  FRESCO_RETURN_IF_ERROR(BuildScene(*scene, file, input.base_dir, job, &info));
  if (const json* mesh = r.Get("mesh")) {
    if (!mesh->is_object())
      return r.Error("mesh", "must be {\"subdivide\": N, \"noise_m\": S, \"seed\": K}");
    ObjectReader m(*mesh, "mesh", file);
    MeshRefineOptions refine;
    FRESCO_RETURN_IF_ERROR(m.Int("subdivide", &refine.subdivide));
    FRESCO_RETURN_IF_ERROR(m.Number("noise_m", &refine.noise_m));
    FRESCO_RETURN_IF_ERROR(m.Unsigned("seed", &refine.seed));
    FRESCO_RETURN_IF_ERROR(m.Finish());
    if (Status s = RefineMesh(refine, &job->scene); !s.ok())
      return Status::Error(file + ": " + s.message());
  }
  job->scene.Bounds(&info.bounds_min, &info.bounds_max);
  info.bounds_min = job->scene.WorldFromLocal(info.bounds_min);
  info.bounds_max = job->scene.WorldFromLocal(info.bounds_max);

  SynthOptions& o = job->options;
  const CameraPathKind kind = info.kind == SceneKind::kStreet   ? CameraPathKind::kWalk
                              : info.kind == SceneKind::kObject ? CameraPathKind::kOrbit
                                                                : CameraPathKind::kHandheld;
  FRESCO_RETURN_IF_ERROR(ReadPathAndDefaults(spec, r, info, kind, /*stream=*/false, &o));

  std::string out;
  FRESCO_RETURN_IF_ERROR(r.String("out", &out));
  job->out_dir = Resolve(input.base_dir, out);
  FRESCO_RETURN_IF_ERROR(ReadCameraKeys(r, &o));
  if (const json* movers = r.Get("movers"))
    FRESCO_RETURN_IF_ERROR(ReadMovers(*movers, file, &o.movers));
  FRESCO_RETURN_IF_ERROR(r.Int("random_movers", &o.random_movers));
  if (const json* region = r.Get("mover_region")) {
    if (!region->is_object())
      return r.Error("mover_region", "must be {\"min\": [..], \"max\": [..]}");
    ObjectReader m(*region, "mover_region", file);
    FRESCO_RETURN_IF_ERROR(m.Vector<3>("min", &o.mover_region_min));
    FRESCO_RETURN_IF_ERROR(m.Vector<3>("max", &o.mover_region_max));
    FRESCO_RETURN_IF_ERROR(m.Finish());
  }
  FRESCO_RETURN_IF_ERROR(r.Rgb("background_rgb", &o.background_rgb));
  FRESCO_RETURN_IF_ERROR(r.Int("threads", &o.threads));
  Status check = o.Check();
  if (!check.ok()) return Status::Error(file + ": " + check.message());
  // Streams last: each starts from every setting above.
  if (const json* streams = r.Get("streams"))
    FRESCO_RETURN_IF_ERROR(ReadStreams(*streams, file, info, job));
  return r.Finish();
}

Status LoadSynthJob(const std::string& spec_path, const std::vector<SynthSpecOverride>& overrides,
                    SynthJob* job) {
  SynthSpecInput input;
  input.name = spec_path;
  if (!fs::is_regular_file(spec_path)) return Status::Error(spec_path + ": no such file");
  FRESCO_RETURN_IF_ERROR(ReadFileToString(spec_path, &input.text));
  input.base_dir = fs::absolute(spec_path).parent_path().string();
  input.overrides = overrides;
  return BuildSynthJob(input, job);
}

std::string SynthOptionsToJson(const SynthOptions& o) {
  auto vec = [](const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); };
  auto rgb = [](const cv::Vec3b& c) { return json::array({c[0], c[1], c[2]}); };
  json j;
  j["frames"] = o.frames;
  j["size"] = json::array({o.width, o.height});
  j["lens"] = LensShortName(o.lens);
  j["hfov_deg"] = o.hfov_deg;
  const CameraPathOptions p = o.PathOptions();
  j["path"] = {{"kind", CameraPathKindName(p.kind)},
               {"target", vec(p.target)},
               {"radius_m", p.radius_m},
               {"height_m", p.height_m},
               {"turns", p.turns},
               {"start_deg", p.start_deg},
               {"wander_m", p.wander_m},
               {"wobble_deg", p.wobble_deg},
               {"look_at_target", p.look_at_target},
               {"pitch_deg", p.pitch_deg},
               {"tilt_deg", p.tilt_deg},
               {"walk_from", vec(p.walk_from)},
               {"walk_to", vec(p.walk_to)},
               {"look_around_deg", p.look_around_deg},
               {"bob_m", p.bob_m}};
  if (p.kind == CameraPathKind::kFixed) j["path"]["eye"] = vec(p.eye);  // other kinds: unused
  j["movers"] = json::array();
  for (const MoverOptions& m : o.movers) {
    j["movers"].push_back({{"shape", MoverShapeName(m.shape)},
                           {"radius_m", m.radius_m},
                           {"rgb", rgb(m.rgb)},
                           {"start", vec(m.start)},
                           {"end", vec(m.end)},
                           {"period_frames", m.period_frames},
                           {"phase", m.phase},
                           {"spin_deg_per_frame", m.spin_deg_per_frame}});
  }
  j["random_movers"] = o.random_movers;
  j["mover_region"] = {{"min", vec(o.mover_region_min)}, {"max", vec(o.mover_region_max)}};
  j["pose_noise_deg"] = o.pose_noise_deg;
  j["pose_noise_m"] = o.pose_noise_m;
  j["exposure"] = o.exposure_jitter;
  j["supersample"] = o.supersample;
  j["background_rgb"] = rgb(o.background_rgb);
  j["seed"] = o.seed;
  j["threads"] = o.threads;
  return j.dump(2);
}

}  // namespace fresco
