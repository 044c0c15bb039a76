// The refinement scenario (refine_scenario.h) with any settings, from the command line: how
// much of the PSNR lost to pose noise a configuration recovers, for other lengths, noise
// levels and seeds than refine_paint_test's. Paints three times (true poses, noisy poses
// with refinement off, noisy poses with the settings given).
//   build/tests/refine_explore FRAMES NOISE_DEG SEED [KEY=VALUE ...]   (KEY under pipeline.)
//   e.g. build/tests/refine_explore 300 0.5 12 refine.mode=robust refine.pose=true
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "pipeline/core/project.h"
#include "tests/paint/refine_scenario.h"

namespace fresco::testing {
namespace {

int Run(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: refine_explore FRAMES NOISE_DEG SEED [KEY=VALUE ...]\n");
    return 2;
  }
  const int frames = std::atoi(argv[1]);
  const double noise = std::atof(argv[2]);
  const int seed = std::atoi(argv[3]);
  std::vector<std::string> sets;
  for (int i = 4; i < argc; ++i) sets.push_back(std::string("pipeline.") + argv[i]);
  Project base;
  base.scene = "x.gltf";
  base.camera = "c.json";
  base.video = "v";
  base.poses = "p.txt";
  Project p;
  Status s = ParseProject(ProjectToJsonText(base), "/tmp/x.json", sets, &p);
  if (!s.ok()) {
    std::fprintf(stderr, "refine_explore: %s\n", s.message().c_str());
    return 2;
  }
  RefineScenario sc;
  if (Status made = MakeRefineScenario(frames, noise, &sc, seed); !made.ok()) {
    std::fprintf(stderr, "refine_explore: %s\n", made.message().c_str());
    return 2;
  }
  PipelineOptions off = p.pipeline;
  off.background.mode = BackgroundMode::kOff;
  off.refine.mode = RefineMode::kOff;
  PaintedScenario perfect, noisy, run;
  if (!PaintScenario(sc, sc.capture.true_poses, off, &perfect).ok() ||
      !PaintScenario(sc, sc.capture.given_poses, off, &noisy).ok())
    return 1;
  PipelineOptions o = p.pipeline;
  o.background.mode = BackgroundMode::kOff;
  if (!PaintScenario(sc, sc.capture.given_poses, o, &run).ok()) return 1;
  const double pp = ScenarioPsnr(sc, perfect.scene), pn = ScenarioPsnr(sc, noisy.scene),
               pr = ScenarioPsnr(sc, run.scene);
  std::printf("seed %d perfect %.2f noisy %.2f run %.2f recovered %.1f %% misalign %.2f refine %.1f ms\n",
              seed, pp, pn, pr, 100 * (pr - pn) / (pp - pn),
              MisalignmentPx(*run.session, *perfect.session), run.refine_ms);
  return 0;
}

}  // namespace
}  // namespace fresco::testing

int main(int argc, char** argv) { return fresco::testing::Run(argc, argv); }
