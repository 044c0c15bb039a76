// Refinement: speed against accuracy (tests/paint/refine_scenario.h: 300 frames, 320x240, a
// handheld half turn in a textured room, 0.5 deg rotation noise on the given poses). Each
// run paints the whole capture with one setting changed from the defaults (refine robust,
// anchored) and reports, besides the wall time, the counters
//   refine_ms     the refine stage per frame (ms)        frame_ms   all stages per frame
//   psnr_db       painted model against the original at the true poses
//   recovered_pct share of the PSNR lost to the noise that refinement recovers
//   build/tests/refine_bench
#include <benchmark/benchmark.h>

#include "tests/paint/refine_scenario.h"

namespace fresco::testing {
namespace {

struct Baseline {
  RefineScenario scenario;
  double perfect_psnr = 0, noisy_psnr = 0;
  Baseline() {
    if (!MakeRefineScenario(300, 0.5, &scenario).ok()) std::abort();
    PipelineOptions options;
    options.background.mode = BackgroundMode::kOff;
    options.refine.mode = RefineMode::kOff;  // the default, `auto`, would refine the noisy one
    PaintedScenario perfect, noisy;
    if (!PaintScenario(scenario, scenario.capture.true_poses, options, &perfect).ok() ||
        !PaintScenario(scenario, scenario.capture.given_poses, options, &noisy).ok())
      std::abort();
    perfect_psnr = ScenarioPsnr(scenario, perfect.scene);
    noisy_psnr = ScenarioPsnr(scenario, noisy.scene);
  }
};

const Baseline& TheBaseline() {
  static const Baseline baseline;
  return baseline;
}

void Run(benchmark::State& state, const PipelineOptions& options) {
  const Baseline& base = TheBaseline();
  PaintedScenario painted;
  for (auto _ : state) {
    painted = PaintedScenario();
    if (!PaintScenario(base.scenario, base.scenario.capture.given_poses, options, &painted).ok())
      state.SkipWithError("painting failed");
  }
  const double psnr = ScenarioPsnr(base.scenario, painted.scene);
  state.counters["refine_ms"] = painted.refine_ms;
  state.counters["frame_ms"] = painted.total_ms;
  state.counters["psnr_db"] = psnr;
  state.counters["recovered_pct"] =
      100 * (psnr - base.noisy_psnr) / (base.perfect_psnr - base.noisy_psnr);
}

PipelineOptions Defaults() {
  PipelineOptions options;
  options.background.mode = BackgroundMode::kOff;
  options.refine.mode = RefineMode::kRobust;
  return options;
}

void BM_RefineWindow(benchmark::State& state) {
  PipelineOptions options = Defaults();
  options.refine.window_px = static_cast<int>(state.range(0));
  Run(state, options);
}
void BM_RefineCorners(benchmark::State& state) {
  PipelineOptions options = Defaults();
  options.refine.max_corners = static_cast<int>(state.range(0));
  Run(state, options);
}
void BM_RefineEveryNFrames(benchmark::State& state) {
  PipelineOptions options = Defaults();
  options.refine.every_n_frames = static_cast<int>(state.range(0));
  Run(state, options);
}
void BM_RefinePaperAnchored(benchmark::State& state) {
  PipelineOptions options = Defaults();
  options.refine.mode = RefineMode::kPaper;
  Run(state, options);
}

BENCHMARK(BM_RefineWindow)->Arg(3)->Arg(7)->Arg(11)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_RefineCorners)->Arg(50)->Arg(300)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_RefineEveryNFrames)->Arg(2)->Arg(5)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_RefinePaperAnchored)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace
}  // namespace fresco::testing
