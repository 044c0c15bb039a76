// End-to-end painting throughput against the memory-bound floor: texels x frames per second
// of the painting loop (depth test, project, sample, update; background, refinement and view
// selection off)
// against OpenCV's cv::remap doing only the bilinear gather of the same buffers' texels from
// the same frames (maps precomputed, not timed; likewise the painting's per-camera ray table),
// both on 2 threads, on 30-frame 640x480
// captures: a street walk with OpenCV5 distortion (`fresco synth` builtin:street, the
// reference) and, for the spread, a hand-held turn in the room (pinhole) and an orbit of the
// blocks (OpenCV8); then four captures held out from the loop's tuning (other seeds and
// lenses, and a façade orbit):
//   BM_Paint/<capture>   items/s = surface texels x frames / painting seconds
//   BM_Remap/<capture>   items/s = the same texels x frames / remap seconds (the remap
//                        gathers only the texels each frame sees: the painting culls the
//                        rest too)
//   BM_PaintVsRemap/<capture>  the two alternated, iteration by iteration: the median
//                        milliseconds of each and the median ratio remap / painting
//   build/tests/throughput_bench --benchmark_min_time=2
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "pipeline/paint/paint_session.h"
#include "pipeline/render/renderer.h"
#include "pipeline/synth/synth_spec.h"
#include "pipeline/synth/synthesize.h"

namespace fresco {
namespace {

// The captures, by the benchmarks' argument.
constexpr const char* kCaptureSpecs[] = {
    R"({"scene": "builtin:street", "frames": 30, "size": [640, 480], "lens": "opencv5",
        "seed": 3})",
    R"({"scene": "builtin:cube-room", "frames": 30, "size": [640, 480], "lens": "pinhole",
        "seed": 3})",
    R"({"scene": "builtin:blocks", "frames": 30, "size": [640, 480], "lens": "opencv8",
        "seed": 3})",
    // Held out: the painting loop was tuned on the three above, never on these.
    R"({"scene": "builtin:street", "frames": 30, "size": [640, 480], "lens": "opencv5",
        "seed": 17})",
    R"({"scene": "builtin:cube-room", "frames": 30, "size": [640, 480], "lens": "opencv4",
        "seed": 17})",
    R"({"scene": "builtin:blocks", "frames": 30, "size": [640, 480], "lens": "pinhole",
        "seed": 17})",
    R"({"scene": {"builtin": "plane", "width_m": 8, "height_m": 5}, "path": {"kind": "orbit"},
        "frames": 30, "size": [640, 480], "lens": "opencv8", "seed": 17})"};
constexpr int kNumCaptures = sizeof(kCaptureSpecs) / sizeof(kCaptureSpecs[0]);
constexpr const char* kCaptureNames[kNumCaptures] = {
    "street_opencv5",         "room_pinhole",         "blocks_opencv8",
    "heldout_street_opencv5", "heldout_room_opencv4", "heldout_blocks_pinhole",
    "heldout_facade_opencv8"};

struct Capture {
  SynthJob job;
  SynthCapture capture;
  PipelineOptions pipeline;
  bool ok = false;

  explicit Capture(int which) {
    SynthSpecInput input;
    input.text = kCaptureSpecs[which];
    if (!BuildSynthJob(input, &job).ok()) return;
    if (!SynthesizeCapture(job.scene, job.options, &capture).ok()) return;
    pipeline.background.mode = BackgroundMode::kOff;
    pipeline.refine.mode = RefineMode::kOff;
    pipeline.select.enabled = false;  // the core loop: no exposure or view selection either
    ok = true;
  }
  std::unique_ptr<PaintSession> Session() const {
    PaintSessionInputs inputs;
    inputs.scene = &job.scene;
    inputs.pipeline = pipeline;
    inputs.typical_camera = &capture.camera;
    for (const auto& p : capture.true_poses) inputs.expected_poses.push_back(p.cam_from_world);
    std::unique_ptr<PaintSession> session;
    if (!PaintSession::Create(inputs, &session).ok()) return nullptr;
    return session;
  }
};

const Capture& TheCapture(int which) {
  static const Capture* captures[kNumCaptures] = {};
  if (!captures[which]) captures[which] = new Capture(which);
  return *captures[which];
}

// Paints the capture's frames in order at their true poses; `each` sees every frame's report.
template <class EachReport>
void PaintAllFrames(const Capture& c, PaintSession* session, EachReport each) {
  FrameReport report;
  for (size_t i = 0; i < c.capture.frames_bgr.size(); ++i) {
    Frame frame;
    frame.index = static_cast<int>(i);
    frame.bgr = c.capture.frames_bgr[i];
    session->PaintFrame(frame, c.capture.camera, c.capture.true_poses[i].cam_from_world, &report);
    each(report);
  }
}

void BM_Paint(benchmark::State& state) {
  const Capture& c = TheCapture(static_cast<int>(state.range(0)));
  state.SetLabel(kCaptureNames[state.range(0)]);
  if (!c.ok) return state.SkipWithError("synth failed");
  cv::setNumThreads(2);
  long long texels = 0;
  std::map<std::string, double> stage_ms;  // summed over every painted frame
  long long frames = 0;
  double tested = 0, in_view = 0;  // texels per frame: projected (chunks not culled), in view
  for (auto _ : state) {
    state.PauseTiming();
    std::unique_ptr<PaintSession> session = c.Session();
    // The camera's ray table is built once per camera, as the remap's maps are (not timed).
    session->PrepareCamera(c.capture.camera);
    texels = session->NumSurfaceTexels();
    state.ResumeTiming();
    PaintAllFrames(c, session.get(), [&](const FrameReport& report) {
      for (const StageReport& stage : report.stages) stage_ms[stage.name] += stage.wall_ms;
      const StageReport* warp = report.Stage("warp");
      tested += warp->metrics.at("texels_tested");
      in_view += warp->metrics.at("texels_in_view");
      ++frames;
    });
    state.PauseTiming();  // tearing the session down is not painting
    session.reset();
    state.ResumeTiming();
  }
  for (const auto& [name, ms] : stage_ms) state.counters[name + "_ms"] = ms / frames;
  state.counters["texels_tested_per_frame"] = tested / frames;
  state.counters["texels_in_view_per_frame"] = in_view / frames;
  state.SetItemsProcessed(state.iterations() * texels *
                          static_cast<long long>(c.capture.frames_bgr.size()));
  state.counters["texels"] = static_cast<double>(texels);
}

// Per frame: where each texel of every buffer that the frame sees falls in it (texels outside
// the frame or behind the camera are left out, as the painting's culling leaves them out), as
// one compact map of rows of 1024. `gathered`: how many texels the maps hold in all.
std::vector<cv::Mat> RemapMaps(const Capture& c, const PaintSession& session, long long* gathered) {
  const Camera& camera = c.capture.camera;
  std::vector<cv::Mat> maps(c.capture.frames_bgr.size());
  *gathered = 0;
  for (size_t i = 0; i < maps.size(); ++i) {
    const Rigid3d cam_from_local =
        CamFromLocal(c.job.scene, c.capture.true_poses[i].cam_from_world);
    std::vector<cv::Vec2f> pixels;
    for (const BaseBuffer& b : session.buffers())
      for (int k = 0; k < b.NumTexels(); ++k) {
        if (!b.on_surface[k]) continue;
        const Eigen::Vector3d p = cam_from_local * b.Point(k).cast<double>();
        Eigen::Vector2d pixel;
        if (p.z() <= 0 || !camera.Project(p, &pixel) || pixel.x() < 0 || pixel.y() < 0 ||
            pixel.x() > camera.width - 1 || pixel.y() > camera.height - 1)
          continue;
        pixels.emplace_back(static_cast<float>(pixel.x()), static_cast<float>(pixel.y()));
      }
    *gathered += static_cast<long long>(pixels.size());
    pixels.resize((pixels.size() + 1023) / 1024 * 1024, cv::Vec2f(-1, -1));
    maps[i] = cv::Mat(pixels, true).reshape(2, static_cast<int>(pixels.size() / 1024));
  }
  return maps;
}

void RemapAll(const Capture& c, const std::vector<cv::Mat>& maps, cv::Mat* out) {
  for (size_t i = 0; i < maps.size(); ++i)
    cv::remap(c.capture.frames_bgr[i], *out, maps[i], cv::noArray(), cv::INTER_LINEAR,
              cv::BORDER_CONSTANT);
}

void BM_Remap(benchmark::State& state) {
  const Capture& c = TheCapture(static_cast<int>(state.range(0)));
  state.SetLabel(kCaptureNames[state.range(0)]);
  if (!c.ok) return state.SkipWithError("synth failed");
  cv::setNumThreads(2);
  const std::unique_ptr<PaintSession> session = c.Session();
  long long gathered = 0;
  const std::vector<cv::Mat> maps = RemapMaps(c, *session, &gathered);
  cv::Mat out;
  for (auto _ : state) RemapAll(c, maps, &out);
  state.counters["texels_in_view_per_frame"] = static_cast<double>(gathered) / maps.size();
  state.SetItemsProcessed(state.iterations() * session->NumSurfaceTexels() *
                          static_cast<long long>(maps.size()));
}

// The ratio read pair by pair: each iteration paints the 30 frames, then remaps them, each
// timed on its own; counters: the median painting and remap milliseconds and the median of
// the pairs' ratios (remap / painting). A slower or faster spell of a shared host then falls
// on both halves of a pair instead of on one benchmark of the two.
void BM_PaintVsRemap(benchmark::State& state) {
  const Capture& c = TheCapture(static_cast<int>(state.range(0)));
  state.SetLabel(kCaptureNames[state.range(0)]);
  if (!c.ok) return state.SkipWithError("synth failed");
  cv::setNumThreads(2);
  long long gathered = 0;
  std::vector<cv::Mat> maps;
  {
    const std::unique_ptr<PaintSession> session = c.Session();
    maps = RemapMaps(c, *session, &gathered);
  }
  std::vector<double> paint_ms, remap_ms, ratio;
  cv::Mat out;
  using Clock = std::chrono::steady_clock;
  const auto ms_since = [](Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  };
  for (auto _ : state) {
    std::unique_ptr<PaintSession> session = c.Session();
    session->PrepareCamera(c.capture.camera);
    Clock::time_point start = Clock::now();
    PaintAllFrames(c, session.get(), [](const FrameReport&) {});
    paint_ms.push_back(ms_since(start));
    start = Clock::now();
    RemapAll(c, maps, &out);
    remap_ms.push_back(ms_since(start));
    ratio.push_back(remap_ms.back() / paint_ms.back());
    state.SetIterationTime((paint_ms.back() + remap_ms.back()) / 1000.0);
  }
  const auto median = [](std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  state.counters["paint_ms"] = median(paint_ms);
  state.counters["remap_ms"] = median(remap_ms);
  state.counters["ratio"] = median(ratio);
  state.counters["ratio_worst"] =
      ratio.empty() ? 0.0 : *std::min_element(ratio.begin(), ratio.end());
}

// Paint and remap of each capture one after the other (the ratio is read within one run);
// --benchmark_filter=/[3-6]/ runs just the held-out captures.
const bool kRegistered = [] {
  for (int i = 0; i < kNumCaptures; ++i) {
    for (auto* b : {benchmark::RegisterBenchmark("BM_Paint", BM_Paint),
                    benchmark::RegisterBenchmark("BM_Remap", BM_Remap)})
      b->Arg(i)->Unit(benchmark::kMillisecond)->UseRealTime();
    benchmark::RegisterBenchmark("BM_PaintVsRemap", BM_PaintVsRemap)
        ->Arg(i)
        ->Unit(benchmark::kMillisecond)
        ->UseManualTime();
  }
  return true;
}();

}  // namespace
}  // namespace fresco
