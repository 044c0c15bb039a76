// Throughput of the per-texel warp kernel (project + grazing test + occlusion test +
// bilinear sample), in texels per second, on one core and on all cores, at 1280x720:
//   BM_WarpKernel          the whole 4 x 3 m wall in view (every texel goes through the
//                          kernel): the kernel's own throughput
//   BM_WarpKernelCloseUp   the camera close to the wall, seeing ~40 % of it: chunk culling
//                          skips the rest, so texels of the buffer per second is higher
//   build/tests/paint_bench --benchmark_min_time=0.5
#include <benchmark/benchmark.h>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/paint/base_buffer.h"
#include "pipeline/paint/frame_warp.h"
#include "pipeline/render/rasterizer.h"
#include "pipeline/render/renderer.h"
#include "pipeline/synth/procedural_scenes.h"

namespace fresco {
namespace {

struct Fixture {
  Scene scene;
  Camera camera;
  Rigid3d cam_from_world;
  BaseBufferSet set;
  cv::Mat frame, depth;

  Fixture(int width, int height, LensModel lens, double distance_m) {
    scene = MakeTexturedPlaneScene(4.0, 3.0);
    std::vector<double> params = {0.8 * width, 0.8 * width, (width - 1) / 2.0, (height - 1) / 2.0};
    if (lens == LensModel::kOpenCV5) params.insert(params.end(), {-0.2, 0.05, 0.001, -0.001, 0.0});
    camera = Camera::FromParams(lens, width, height, params);
    // distance_m in front of the plane, looking at -Z, slightly oblique.
    cam_from_world = Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) *
                                                Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY())),
                             Eigen::Vector3d(0, 0, distance_m));
    cam_from_world.translation =
        -(cam_from_world.rotation * Eigen::Vector3d(0.3, 0.1, distance_m));
    const Grouping g = ComputeGrouping(scene.mesh, ComputeAdjacency(scene.mesh), 20.0);
    BaseBufferOptions options;
    options.texel_size_m = distance_m / camera.fx;  // ~1 texel per pixel
    options.max_buffer_texels = 1 << 24;
    set = BuildBaseBuffers(scene.mesh, g, options);
    RenderOutput out;
    Renderer(camera, RenderOptions()).Render(scene, cam_from_world, &out);
    cv::cvtColor(out.rgba, frame, cv::COLOR_RGBA2BGR);
    depth = out.depth;
  }
};

void RunWarp(benchmark::State& state, Fixture& f) {
  const int threads = static_cast<int>(state.range(0));
  cv::setNumThreads(threads);
  FrameView view;
  view.camera = &f.camera;
  view.cam_from_local = CamFromLocal(f.scene, f.cam_from_world);
  view.centre_local = view.cam_from_local.Centre();
  view.frame_bgr = &f.frame;
  view.depth = &f.depth;
  view.bounds = ComputeNormalizedBounds(f.camera);
  WarpOptions options;
  WarpedBuffer warped;
  long long texels = 0, tested = 0, visible = 0;
  for (auto _ : state) {
    for (const BaseBuffer& b : f.set.buffers) {
      WarpFrameToBuffer(b, view, options, &warped);
      texels += b.NumTexels();
      tested += warped.texels_tested;
      visible += warped.visible;
    }
  }
  state.counters["buffer_texels_per_s"] =
      benchmark::Counter(static_cast<double>(texels), benchmark::Counter::kIsRate);
  state.counters["kernel_texels_per_s"] =
      benchmark::Counter(static_cast<double>(tested), benchmark::Counter::kIsRate);
  state.counters["visible_fraction"] = static_cast<double>(visible) / std::max(1LL, texels);
  cv::setNumThreads(-1);
}

void BM_WarpKernel(benchmark::State& state) {
  static Fixture* pinhole = new Fixture(1280, 720, LensModel::kPinhole, 3.8);
  static Fixture* distorted = new Fixture(1280, 720, LensModel::kOpenCV5, 3.8);
  RunWarp(state, state.range(1) ? *distorted : *pinhole);
}
BENCHMARK(BM_WarpKernel)->ArgsProduct({{1, 2}, {0, 1}})->ArgNames({"threads", "distorted"})->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_WarpKernelCloseUp(benchmark::State& state) {
  static Fixture* pinhole = new Fixture(1280, 720, LensModel::kPinhole, 2.5);
  static Fixture* distorted = new Fixture(1280, 720, LensModel::kOpenCV5, 2.5);
  RunWarp(state, state.range(1) ? *distorted : *pinhole);
}
BENCHMARK(BM_WarpKernelCloseUp)->ArgsProduct({{1, 2}, {0, 1}})->ArgNames({"threads", "distorted"})->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_DepthRaster(benchmark::State& state) {
  static Fixture* f = new Fixture(1280, 720, LensModel::kPinhole, 3.8);
  Rasterizer raster(f->camera, RasterOptions());
  RasterOutput out;
  for (auto _ : state) raster.Rasterize(f->scene.mesh, CamFromLocal(f->scene, f->cam_from_world), &out);
}
BENCHMARK(BM_DepthRaster)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace fresco
