// Refinement in the pipeline, against ground truth (tests/paint/refine_scenario.h): 300
// frames (10 s at 30 fps) of a handheld half turn in a textured room, whose given poses carry
// 0.5 deg of rotation noise, painted with refinement off, in the paper's mode and in the
// robust mode, each with and without consensus anchoring (refine_anchor.h). The painted
// model is re-rendered at the true poses and compared with the original; each painted
// buffer is registered to the one painted at the true poses (misalignment, texels).
// Registration alone makes the frames agree with the buffer but inherits (and random-walks)
// the buffer's offset; anchoring removes most of it. The target is >= 80 % of the
// PSNR the noise costs: per-buffer homographies reach 79 % (docs/results.md), held here at
// >= 75 %; correcting the frame's pose from all buffers' matches reaches 86 %, held at >= 80 %.
#include <cstdio>

#include <gtest/gtest.h>

#include "tests/paint/refine_scenario.h"

namespace fresco::testing {
namespace {

class RefinePainting : public ::testing::Test {
 protected:
  // Refinement alone: no background model; the sharpest view per texel, as every setting with
  // refinement on paints (`update: auto` keeps it there), so that a row without refinement
  // differs from one with it by the refinement only.
  static PipelineOptions Unrefined() {
    PipelineOptions options;
    options.background.mode = BackgroundMode::kOff;
    options.refine.mode = RefineMode::kOff;
    options.update = UpdatePolicy::kQuality;
    return options;
  }
  static void SetUpTestSuite() {
    scenario_ = new RefineScenario;
    ASSERT_TRUE(MakeRefineScenario(300, 0.5, scenario_).ok());
    PipelineOptions options = Unrefined();
    perfect_ = new PaintedScenario;
    ASSERT_TRUE(PaintScenario(*scenario_, scenario_->capture.true_poses, options, perfect_).ok());
    perfect_psnr_ = ScenarioPsnr(*scenario_, perfect_->scene);
  }
  static void TearDownTestSuite() {
    delete perfect_;
    delete scenario_;
  }

  struct Row {
    double psnr = 0, recovered = 0, misalignment = 0;
    long long painted_texels = 0;  // on-surface texels painted, all buffers
    PaintedScenario painted;
  };
  static long long PaintedTexels(const PaintSession& session) {
    long long n = 0;
    for (const PaintedBuffer& p : session.painted()) n += p.painted_surface_texels;
    return n;
  }
  static Row Measure(const char* name, const std::vector<PosedImage>& poses,
                     const PipelineOptions& options, double noisy_psnr) {
    Row row;
    EXPECT_TRUE(PaintScenario(*scenario_, poses, options, &row.painted).ok());
    row.psnr = ScenarioPsnr(*scenario_, row.painted.scene);
    if (noisy_psnr == 0) noisy_psnr = row.psnr;  // this is the noisy run
    row.recovered = (row.psnr - noisy_psnr) / (perfect_psnr_ - noisy_psnr);
    row.misalignment = MisalignmentPx(*row.painted.session, *perfect_->session);
    row.painted_texels = PaintedTexels(*row.painted.session);
    std::printf(
        "%-28s PSNR %.2f dB (recovers %4.0f %%), misalignment %.2f texels, registration "
        "residual %.2f -> %.2f texels, %d registrations applied, refine %.1f ms/frame, "
        "%.1f %% of the texels painted at the true poses\n",
        name, row.psnr, 100 * row.recovered, row.misalignment, row.painted.refine_before_px,
        row.painted.refine_after_px, row.painted.refined, row.painted.refine_ms,
        100.0 * row.painted_texels / PaintedTexels(*perfect_->session));
    return row;
  }

  static RefineScenario* scenario_;
  static PaintedScenario* perfect_;
  static double perfect_psnr_;
};
RefineScenario* RefinePainting::scenario_ = nullptr;
PaintedScenario* RefinePainting::perfect_ = nullptr;
double RefinePainting::perfect_psnr_ = 0;

TEST_F(RefinePainting, AnchoredRobustRefinementRecoversMostOfThePsnrLostToPoseNoise) {
  const std::vector<PosedImage>& noisy_poses = scenario_->capture.given_poses;
  PipelineOptions options = Unrefined();
  const Row noisy = Measure("0.5 deg noise, no refine", noisy_poses, options, 0);  // recovers 0
  const double noisy_psnr = noisy.psnr;
  std::printf("perfect poses: PSNR %.2f dB\n", perfect_psnr_);
  options.refine.pose = false;  // per-buffer homographies first
  options.refine.anchor = false;
  options.refine.mode = RefineMode::kPaper;
  Measure("paper", noisy_poses, options, noisy_psnr);
  options.refine.mode = RefineMode::kRobust;
  const Row robust_free = Measure("robust", noisy_poses, options, noisy_psnr);
  options.refine.anchor = true;
  options.refine.mode = RefineMode::kPaper;
  const Row paper = Measure("paper, anchored", noisy_poses, options, noisy_psnr);
  options.refine.mode = RefineMode::kRobust;
  const Row robust = Measure("robust, anchored", noisy_poses, options, noisy_psnr);
  options.refine.pose = true;
  const Row pose = Measure("robust, anchored, pose (default)", noisy_poses, options, noisy_psnr);

  EXPECT_GT(perfect_psnr_ - noisy_psnr, 5.0);  // the noise costs something: the test can fail
  // Per-buffer homographies: 79 % (measured).
  EXPECT_GE(robust.recovered, 0.75);
  EXPECT_GT(robust.psnr, robust_free.psnr + 3.0);  // anchoring is what recovers it
  EXPECT_GT(robust.psnr, paper.psnr + 2.0);
  EXPECT_LT(robust.misalignment, 0.6 * noisy.misalignment);
  EXPECT_LT(robust.painted.refine_after_px, 0.5 * robust.painted.refine_before_px);
  // One pose correction per frame from every buffer's matches (refine_pose.h) does better
  // than one homography per buffer: measured 86 % (seeds 12, 13: 85 %, 84 %).
  EXPECT_GE(pose.recovered, 0.80);
  EXPECT_GT(pose.psnr, robust.psnr + 0.3);
  EXPECT_LT(pose.misalignment, robust.misalignment);
  // Anchoring moves only content the frame sees (and repaints): what the camera has turned
  // away from keeps its paint. Moving it on old samples eroded its edges at every move.
  const long long perfect_texels = PaintedTexels(*perfect_->session);
  EXPECT_GE(pose.painted_texels, 0.97 * perfect_texels);
  EXPECT_GE(robust.painted_texels, 0.97 * perfect_texels);
}

// Refinement must not damage a capture whose poses are right: registration noise applied
// frame after frame would random-walk the buffers (min_correction_px stops that).
TEST_F(RefinePainting, CorrectPosesStayCorrectWithRefinementOn) {
  PipelineOptions options;
  options.background.mode = BackgroundMode::kOff;
  options.refine.mode = RefineMode::kRobust;
  options.refine.pose = false;
  const Row row =
      Measure("perfect poses, robust", scenario_->capture.true_poses, options, perfect_psnr_ - 1);
  EXPECT_GT(row.psnr, perfect_psnr_ - 0.3);
  EXPECT_LT(row.misalignment, 0.3);
  options.refine.pose = true;
  const Row pose = Measure("perfect poses, robust, pose", scenario_->capture.true_poses, options,
                           perfect_psnr_ - 1);
  EXPECT_GT(pose.psnr, perfect_psnr_ - 0.3);
  EXPECT_LT(pose.misalignment, 0.3);
  options.refine.min_correction_px = 0;  // without the dead band, the buffers drift
  const Row drifting = Measure("perfect poses, no dead band", scenario_->capture.true_poses,
                               options, perfect_psnr_ - 1);
  EXPECT_LT(drifting.psnr, row.psnr);
}

}  // namespace
}  // namespace fresco::testing
