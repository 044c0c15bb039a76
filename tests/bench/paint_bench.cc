// Throughput of the per-texel warp kernel (project + grazing test + occlusion test +
// bilinear sample), in texels per second, on one core and on all cores, at 1280x720:
//   BM_WarpKernel          the whole 4 x 3 m wall in view (every texel goes through the
//                          kernel): the kernel's own throughput
//   BM_WarpKernelCloseUp   the camera close to the wall, seeing ~40 % of it: chunk culling
//                          skips the rest, so texels of the buffer per second is higher
//   BM_DepthRaster         the occlusion stage's depth map, depth only and full
//   BM_DecodeFrame         decoding one PNG frame, as written by `fresco synth` and before
//   BM_BackgroundUpdate    the robust background model's update (classify, learn, clean) of
//                          the wall's warped samples, a cycle of 8 frames with noise, an
//                          exposure change and a square mover
//   build/tests/paint_bench --benchmark_min_time=0.5
#include <benchmark/benchmark.h>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/png_encode.h"
#include "pipeline/paint/background_model.h"
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
    cam_from_world.translation = -(cam_from_world.rotation * Eigen::Vector3d(0.3, 0.1, distance_m));
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
BENCHMARK(BM_WarpKernel)
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->ArgNames({"threads", "distorted"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_WarpKernelCloseUp(benchmark::State& state) {
  static Fixture* pinhole = new Fixture(1280, 720, LensModel::kPinhole, 2.5);
  static Fixture* distorted = new Fixture(1280, 720, LensModel::kOpenCV5, 2.5);
  RunWarp(state, state.range(1) ? *distorted : *pinhole);
}
BENCHMARK(BM_WarpKernelCloseUp)
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->ArgNames({"threads", "distorted"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// depth_only 1: RasterizeDepth (the painting's occlusion stage); 0: depth, ids, barycentrics.
void BM_DepthRaster(benchmark::State& state) {
  static Fixture* f = new Fixture(1280, 720, LensModel::kPinhole, 3.8);
  Rasterizer raster(f->camera, RasterOptions());
  RasterOutput out;
  const Rigid3d cam_from_local = CamFromLocal(f->scene, f->cam_from_world);
  for (auto _ : state) {
    if (state.range(0))
      raster.RasterizeDepth(f->scene.mesh, cam_from_local, &out.depth);
    else
      raster.Rasterize(f->scene.mesh, cam_from_local, &out);
  }
}
BENCHMARK(BM_DepthRaster)
    ->Arg(0)
    ->Arg(1)
    ->ArgName("depth_only")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Decoding one 1280x720 frame (one thread, cv::imdecode), as `fresco run` does for every
// frame of a capture: fast 1: written by EncodeFastDecodingPng (what `fresco synth` writes);
// 0: OpenCV's encoder at compression 3 (what it wrote before). The frame: the procedural cube
// room seen from its middle, at an angle (four textured faces in view).
void BM_DecodeFrame(benchmark::State& state) {
  static const cv::Mat frame = [] {
    Scene scene;
    if (!MakeCubeRoomScene(CubeRoomOptions(), &scene).ok()) return cv::Mat();
    const Camera camera =
        Camera::FromParams(LensModel::kPinhole, 1280, 720, {914.0, 914.0, 639.5, 359.5});
    // World y up; the camera looks level along world +z turned 40 deg, 10 deg down.
    const Eigen::Quaterniond world_from_cam =
        Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY())) *
        Eigen::Quaterniond(Eigen::AngleAxisd(-0.17, Eigen::Vector3d::UnitX())) *
        Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()));
    const Eigen::Vector3d centre(0.2, 1.5, -0.3);
    const Rigid3d cam_from_world(world_from_cam.conjugate(),
                                 -(world_from_cam.conjugate() * centre));
    RenderOutput out;
    Renderer(camera, RenderOptions()).Render(scene, cam_from_world, &out);
    cv::Mat bgr;
    cv::cvtColor(out.rgba, bgr, cv::COLOR_RGBA2BGR);
    return bgr;
  }();
  std::vector<uint8_t> png;
  if (frame.empty()) state.SkipWithError("no cube room");
  if (state.range(0)) {
    if (!EncodeFastDecodingPng(frame, &png).ok()) state.SkipWithError("encoding failed");
  } else {
    cv::imencode(".png", frame, png, {cv::IMWRITE_PNG_COMPRESSION, 3});
  }
  cv::setNumThreads(1);
  for (auto _ : state) benchmark::DoNotOptimize(cv::imdecode(png, cv::IMREAD_COLOR));
  cv::setNumThreads(-1);
  state.counters["bytes"] = static_cast<double>(png.size());
}
BENCHMARK(BM_DecodeFrame)
    ->Arg(0)
    ->Arg(1)
    ->ArgName("fast")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_BackgroundUpdate(benchmark::State& state) {
  static Fixture* f = new Fixture(1280, 720, LensModel::kPinhole, 3.8);
  const int threads = static_cast<int>(state.range(0));
  const BaseBuffer& buffer = f->set.buffers[0];
  FrameView view;
  view.camera = &f->camera;
  view.cam_from_local = CamFromLocal(f->scene, f->cam_from_world);
  view.centre_local = view.cam_from_local.Centre();
  view.depth = &f->depth;
  view.bounds = ComputeNormalizedBounds(f->camera);
  // 8 frames: sensor noise (sigma 3), every 4th brighter by 10 %, a 200 x 200 px square
  // crossing the view; warped once, outside the timing.
  std::vector<WarpedBuffer> warped(8);
  cv::RNG rng(7);
  for (int i = 0; i < 8; ++i) {
    cv::Mat noise(f->frame.size(), CV_16SC3), frame;
    rng.fill(noise, cv::RNG::NORMAL, 0, 3);
    f->frame.convertTo(frame, CV_16SC3, i % 4 == 3 ? 1.1 : 1.0);
    cv::Mat(frame + noise).convertTo(frame, CV_8UC3);
    cv::rectangle(frame, cv::Rect(100 + 120 * i, 260, 200, 200), cv::Scalar(40, 200, 90), -1);
    view.frame_bgr = &frame;
    WarpFrameToBuffer(buffer, view, WarpOptions(), &warped[i]);
  }
  BackgroundOptions options;
  options.mode = BackgroundMode::kRobust;
  BufferBackground model;
  model.Init(buffer, options);
  BackgroundFrame frame;
  cv::setNumThreads(threads);
  long long observed = 0, masked = 0;
  int i = 0;
  for (auto _ : state) {
    model.Update(buffer, warped[i % 8], i % 4 == 3 ? 1.1f : 1.0f, false, false, &frame);
    observed += frame.observed;
    masked += frame.masked;
    ++i;
  }
  cv::setNumThreads(-1);
  state.counters["texels_per_s"] =
      benchmark::Counter(static_cast<double>(observed), benchmark::Counter::kIsRate);
  state.counters["masked_fraction"] = static_cast<double>(masked) / std::max(1LL, observed);
}
BENCHMARK(BM_BackgroundUpdate)
    ->Arg(1)
    ->Arg(2)
    ->ArgName("threads")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace fresco
