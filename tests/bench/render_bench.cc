// Speed of the CPU renderer: the per-frame depth + triangle-id rasterization the painting
// pipeline runs, and full colour renders. Scenes: a tessellated sphere in front of a wall
// (~1k or ~10k triangles) filling most of the image.
//   build-render/tests/render_bench --benchmark_min_time=0.5
#include <cmath>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/camera.h"
#include "pipeline/core/scene.h"
#include "pipeline/render/rasterizer.h"
#include "pipeline/render/renderer.h"

namespace fresco {
namespace {

// A UV sphere (radius 1, at the origin) with about `triangles` triangles, plus a textured
// wall 1.5 m behind it; camera 3 m in front, looking at the sphere.
Scene MakeScene(int triangles) {
  Scene scene;
  Texture texture;
  cv::Mat rgb(256, 256, CV_8UC3);
  cv::RNG rng(1);
  rng.fill(rgb, cv::RNG::UNIFORM, 0, 256);
  cv::cvtColor(rgb, texture.rgba, cv::COLOR_RGB2RGBA);  // opaque
  scene.textures.push_back(texture);
  Material material;
  material.base_color_texture = 0;
  scene.materials.push_back(material);
  TriangleMesh& mesh = scene.mesh;
  const int rings = std::max(2, static_cast<int>(std::sqrt(triangles / 2.0)));
  const int segments = rings;
  for (int i = 0; i <= rings; ++i) {
    const double theta = M_PI * i / rings;
    for (int j = 0; j <= segments; ++j) {
      const double phi = 2 * M_PI * j / segments;
      mesh.vertices.emplace_back(std::sin(theta) * std::cos(phi), std::cos(theta),
                                 std::sin(theta) * std::sin(phi));
    }
  }
  auto add = [&](int a, int b, int c, float u, float v) {
    mesh.triangles.emplace_back(a, b, c);
    mesh.uvs.push_back(
        {Eigen::Vector2f(u, v), Eigen::Vector2f(u + 0.01f, v), Eigen::Vector2f(u, v + 0.01f)});
    mesh.material.push_back(0);
    mesh.has_uv.push_back(true);
  };
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      const int a = i * (segments + 1) + j, b = a + 1, c = a + segments + 1, d = c + 1;
      const float u = static_cast<float>(j) / segments, v = static_cast<float>(i) / rings;
      add(a, c, b, u, v);
      add(b, c, d, u, v);
    }
  }
  const int base = static_cast<int>(mesh.vertices.size());
  mesh.vertices.insert(mesh.vertices.end(),
                       {Eigen::Vector3d(-6, -5, 2.5), Eigen::Vector3d(6, -5, 2.5),
                        Eigen::Vector3d(6, 5, 2.5), Eigen::Vector3d(-6, 5, 2.5)});
  mesh.triangles.emplace_back(base, base + 1, base + 2);
  mesh.triangles.emplace_back(base, base + 2, base + 3);
  for (int k = 0; k < 2; ++k) {
    mesh.uvs.push_back({Eigen::Vector2f(0, 0), Eigen::Vector2f(4, 0), Eigen::Vector2f(4, 4)});
    mesh.material.push_back(0);
    mesh.has_uv.push_back(true);
  }
  return scene;
}

Camera MakeCamera(int width, bool distorted) {
  const int height = width == 640 ? 480 : 720;
  const double f = 0.8 * width;
  if (!distorted) {
    return Camera::FromParams(LensModel::kPinhole, width, height,
                              {f, f, (width - 1) / 2.0, (height - 1) / 2.0});
  }
  return Camera::FromParams(
      LensModel::kOpenCV8, width, height,
      {f, f, (width - 1) / 2.0, (height - 1) / 2.0, -0.3, 0.08, 1e-3, -5e-4, -0.005, 0.01, 0, 0});
}

// Camera 3 m in front of the sphere (along -z), looking at it.
Rigid3d Pose() { return Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 3.0)); }

// Args: image width (640 -> 640x480, 1280 -> 1280x720), triangles, distorted (0/1).
void BM_RasterDepthId(benchmark::State& state) {
  const Scene scene = MakeScene(static_cast<int>(state.range(1)));
  const Rasterizer rasterizer(MakeCamera(static_cast<int>(state.range(0)), state.range(2) != 0),
                              RasterOptions());
  RasterOutput out;
  for (auto _ : state) {
    rasterizer.Rasterize(scene.mesh, Pose(), &out);
    benchmark::DoNotOptimize(out.depth.data);
  }
  state.counters["triangles"] = scene.mesh.NumTriangles();
  state.counters["covered"] =
      cv::countNonZero(out.triangle_id >= 0) / static_cast<double>(out.triangle_id.total());
}
BENCHMARK(BM_RasterDepthId)
    ->Args({640, 1000, 0})
    ->Args({640, 10000, 0})
    ->Args({1280, 1000, 0})
    ->Args({1280, 10000, 0})
    ->Args({640, 10000, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Threads: the same 640x480 rasterization with cv::setNumThreads(N). Args: triangles, N.
void BM_RasterThreads(benchmark::State& state) {
  const Scene scene = MakeScene(static_cast<int>(state.range(0)));
  const Rasterizer rasterizer(MakeCamera(640, false), RasterOptions());
  const int previous = cv::getNumThreads();
  cv::setNumThreads(static_cast<int>(state.range(1)));
  RasterOutput out;
  for (auto _ : state) {
    rasterizer.Rasterize(scene.mesh, Pose(), &out);
    benchmark::DoNotOptimize(out.depth.data);
  }
  cv::setNumThreads(previous);
}
BENCHMARK(BM_RasterThreads)
    ->Args({1000, 1})
    ->Args({1000, 2})
    ->Args({10000, 1})
    ->Args({10000, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Full colour render. Args: width, triangles, supersample.
void BM_RenderColour(benchmark::State& state) {
  const Scene scene = MakeScene(static_cast<int>(state.range(1)));
  RenderOptions options;
  options.raster.supersample = static_cast<int>(state.range(2));
  const Renderer renderer(MakeCamera(static_cast<int>(state.range(0)), false), options);
  RenderOutput out;
  for (auto _ : state) {
    renderer.Render(scene, Pose(), &out);
    benchmark::DoNotOptimize(out.rgba.data);
  }
}
BENCHMARK(BM_RenderColour)
    ->Args({640, 1000, 1})
    ->Args({640, 10000, 1})
    ->Args({640, 10000, 2})
    ->Args({1280, 10000, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Once per camera: the ray table (Unproject of every sample). Args: width, distorted.
void BM_RayTable(benchmark::State& state) {
  Camera camera = MakeCamera(static_cast<int>(state.range(0)), state.range(1) != 0);
  for (auto _ : state) {
    camera.cx += 1e-6;  // a camera of its own each time: rasterizers of one camera share it
    Rasterizer rasterizer(camera, RasterOptions());
    benchmark::DoNotOptimize(&rasterizer);
  }
}
BENCHMARK(BM_RayTable)
    ->Args({640, 0})
    ->Args({640, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace fresco
