// The painting's depth stage on large meshes: Fresco's ray-table raster (RasterizeDepth)
// against Embree ray casting of the same rays (BVH built once, as a static scene allows;
// rtcIntersect1 per ray, or rtcIntersect8 per 8 neighbouring rays of a row; rows in
// parallel), all on all cores:
//   BM_DepthRasterRoom1M / BM_DepthEmbreeRoom1M   the room subdivided to 1.0 M triangles,
//                                                 1280x720 from inside (a third in view)
//   BM_DepthRasterSceaux / BM_DepthEmbreeSceaux   OpenMVS's refined Sceaux mesh (175 k
//                                                 triangles), photo 00004's pose, 1416x1064
//                                                 (skipped without ../shared/data)
// Built only when Embree is installed (apt-get install libembree-dev):
//   build/tests/depth_bench --benchmark_min_time=1
#include <cstdlib>
#include <filesystem>
#include <memory>

#include <benchmark/benchmark.h>
#include <embree3/rtcore.h>
#include <opencv2/core/utility.hpp>

#include "pipeline/core/camera.h"
#include "pipeline/core/poses.h"
#include "pipeline/core/scene.h"
#include "pipeline/render/rasterizer.h"
#include "pipeline/render/renderer.h"
#include "pipeline/synth/mesh_refine.h"
#include "pipeline/synth/procedural_scenes.h"

namespace fresco {
namespace {

struct DepthCase {
  Scene scene;
  Camera camera;
  Rigid3d cam_from_local;
  bool ok = false;
};

DepthCase Room1M() {
  DepthCase c;
  CubeRoomOptions room;
  room.procedural_texture_px = 16;
  if (!MakeCubeRoomScene(room, &c.scene).ok()) return c;
  MeshRefineOptions refine;
  refine.subdivide = 290;
  if (!RefineMesh(refine, &c.scene).ok()) return c;
  c.camera = Camera::FromParams(LensModel::kPinhole, 1280, 720, {914, 914, 639.5, 359.5});
  // From the room's middle, looking at a corner, slightly down.
  const Eigen::Quaterniond look(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY()) *
                                Eigen::AngleAxisd(M_PI + 0.1, Eigen::Vector3d::UnitX()));
  const Rigid3d cam_from_world(look.inverse(), -(look.inverse() * Eigen::Vector3d(0.2, 1.5, 0.3)));
  c.cam_from_local = CamFromLocal(c.scene, cam_from_world);
  c.ok = true;
  return c;
}

DepthCase Sceaux() {
  DepthCase c;
  const char* env = std::getenv("FRESCO_SHARED_DATA");
  const std::string data = (env && *env ? std::string(env) : std::string(FRESCO_BENCH_SHARED_DATA)) +
                           "/sceaux-castle-openmvs";
  if (!std::filesystem::exists(data)) return c;
  if (!LoadScene(data + "/openmvs_original/scene_mesh_refine.ply", SceneLoadOptions(), &c.scene).ok())
    return c;
  std::map<int, Camera> cameras;
  std::vector<PosedImage> images;
  if (!ReadColmapCameras(data + "/colmap_sparse_txt/cameras.txt", &cameras).ok() ||
      !ReadColmapImages(data + "/colmap_sparse_txt/images.txt", &images).ok() ||
      images.size() < 5 || cameras.empty())
    return c;
  c.camera = cameras.begin()->second;
  c.cam_from_local = CamFromLocal(c.scene, images[4].cam_from_world);
  c.ok = true;
  return c;
}

void RunRaster(benchmark::State& state, const DepthCase& c) {
  if (!c.ok) return state.SkipWithError("data not available");
  const Rasterizer raster(c.camera, RasterOptions());
  cv::Mat depth;
  raster.RasterizeDepth(c.scene.mesh, c.cam_from_local, &depth);  // clusters cached
  for (auto _ : state) raster.RasterizeDepth(c.scene.mesh, c.cam_from_local, &depth);
  state.counters["hit_fraction"] =
      static_cast<double>(cv::countNonZero(depth < std::numeric_limits<float>::infinity())) /
      depth.total();
}

// Embree's scene of a mesh, built once.
struct EmbreeScene {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  explicit EmbreeScene(const TriangleMesh& mesh) {
    device = rtcNewDevice(nullptr);
    scene = rtcNewScene(device);
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
        geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.vertices.size()));
    for (size_t i = 0; i < mesh.vertices.size(); ++i)
      for (int k = 0; k < 3; ++k) v[3 * i + k] = static_cast<float>(mesh.vertices[i][k]);
    auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
        geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), mesh.triangles.size()));
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k) idx[3 * t + k] = static_cast<unsigned>(mesh.triangles[t][k]);
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(scene);
  }
  ~EmbreeScene() {
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
  }
};

// What both Embree runs use: the scene, the exact ray per pixel (the raster's ray table) and
// the camera in the mesh's local frame.
struct EmbreeView {
  EmbreeScene embree;
  Rasterizer raster;
  Eigen::Matrix3d local_from_cam;
  Eigen::Vector3d centre;
  explicit EmbreeView(const DepthCase& c)
      : embree(c.scene.mesh),
        raster(c.camera, RasterOptions()),
        local_from_cam(c.cam_from_local.RotationMatrix().transpose()),
        centre(c.cam_from_local.Centre()) {}
};

// Casts every row of the camera's rays with cast_row(view, context, row, depth_row), rows in
// parallel, and times it.
template <class CastRow>
void RunEmbreeRows(benchmark::State& state, const DepthCase& c, bool coherent, CastRow cast_row) {
  if (!c.ok) return state.SkipWithError("data not available");
  const EmbreeView v(c);
  cv::Mat depth(c.camera.height, c.camera.width, CV_32F);
  for (auto _ : state) {
    cv::parallel_for_(cv::Range(0, c.camera.height), [&](const cv::Range& range) {
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      if (coherent) context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
      for (int r = range.start; r < range.end; ++r) cast_row(v, &context, r, depth.ptr<float>(r));
    });
  }
  state.counters["hit_fraction"] =
      static_cast<double>(cv::countNonZero(depth < std::numeric_limits<float>::infinity())) /
      depth.total();
}

// The ray of pixel (col, row) in the mesh's frame: direction (x, y, 1) in the camera, so the
// hit distance t is the camera depth z.
Eigen::Vector3d RayDirection(const EmbreeView& v, int col, int row) {
  const Eigen::Vector2f ray = v.raster.Ray(col, row);
  return v.local_from_cam * Eigen::Vector3d(ray.x(), ray.y(), 1.0);
}

constexpr float kInfinity = std::numeric_limits<float>::infinity();

// One ray at a time (rtcIntersect1).
void RunEmbree(benchmark::State& state, const DepthCase& c) {
  RunEmbreeRows(state, c, false, [&](const EmbreeView& v, RTCIntersectContext* context, int r,
                                     float* out) {
    for (int col = 0; col < c.camera.width; ++col) {
      const Eigen::Vector3d d = RayDirection(v, col, r);
      RTCRayHit hit{};
      hit.ray.org_x = static_cast<float>(v.centre.x());
      hit.ray.org_y = static_cast<float>(v.centre.y());
      hit.ray.org_z = static_cast<float>(v.centre.z());
      hit.ray.dir_x = static_cast<float>(d.x());
      hit.ray.dir_y = static_cast<float>(d.y());
      hit.ray.dir_z = static_cast<float>(d.z());
      hit.ray.tnear = 1e-3f;
      hit.ray.tfar = kInfinity;
      hit.ray.mask = 0xffffffffu;
      hit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(v.embree.scene, context, &hit);
      out[col] = hit.hit.geomID == RTC_INVALID_GEOMETRY_ID ? kInfinity : hit.ray.tfar;
    }
  });
}

// Packets of 8 neighbouring rays of a row (rtcIntersect8): coherent rays share BVH traversal.
void RunEmbree8(benchmark::State& state, const DepthCase& c) {
  RunEmbreeRows(state, c, true, [&](const EmbreeView& v, RTCIntersectContext* context, int r,
                                    float* out) {
    alignas(32) int valid[8];
    alignas(32) RTCRayHit8 hit;
    for (int col0 = 0; col0 < c.camera.width; col0 += 8) {
      for (int i = 0; i < 8; ++i) {
        const int col = std::min(col0 + i, c.camera.width - 1);
        valid[i] = col0 + i < c.camera.width ? -1 : 0;
        const Eigen::Vector3d d = RayDirection(v, col, r);
        hit.ray.org_x[i] = static_cast<float>(v.centre.x());
        hit.ray.org_y[i] = static_cast<float>(v.centre.y());
        hit.ray.org_z[i] = static_cast<float>(v.centre.z());
        hit.ray.dir_x[i] = static_cast<float>(d.x());
        hit.ray.dir_y[i] = static_cast<float>(d.y());
        hit.ray.dir_z[i] = static_cast<float>(d.z());
        hit.ray.tnear[i] = 1e-3f;
        hit.ray.tfar[i] = kInfinity;
        hit.ray.mask[i] = 0xffffffffu;
        hit.ray.flags[i] = 0;
        hit.ray.time[i] = 0;
        hit.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
      }
      rtcIntersect8(valid, v.embree.scene, context, &hit);
      for (int i = 0; i < 8 && col0 + i < c.camera.width; ++i)
        out[col0 + i] = hit.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID ? kInfinity : hit.ray.tfar[i];
    }
  });
}

const DepthCase& RoomCase() {
  static const DepthCase* c = new DepthCase(Room1M());
  return *c;
}
const DepthCase& SceauxCase() {
  static const DepthCase* c = new DepthCase(Sceaux());
  return *c;
}

void BM_DepthRasterRoom1M(benchmark::State& s) { RunRaster(s, RoomCase()); }
void BM_DepthEmbreeRoom1M(benchmark::State& s) { RunEmbree(s, RoomCase()); }
void BM_DepthEmbree8Room1M(benchmark::State& s) { RunEmbree8(s, RoomCase()); }
void BM_DepthRasterSceaux(benchmark::State& s) { RunRaster(s, SceauxCase()); }
void BM_DepthEmbree8Sceaux(benchmark::State& s) { RunEmbree8(s, SceauxCase()); }
void BM_DepthEmbreeSceaux(benchmark::State& s) { RunEmbree(s, SceauxCase()); }
BENCHMARK(BM_DepthRasterRoom1M)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DepthEmbreeRoom1M)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DepthEmbree8Room1M)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DepthRasterSceaux)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DepthEmbree8Sceaux)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DepthEmbreeSceaux)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace fresco
