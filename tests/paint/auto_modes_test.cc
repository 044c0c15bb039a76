// The `auto` modes (pipeline/paint/auto_modes.h) against ground truth: the synthetic capture
// knows whether its poses carry noise and whether anything moves, the session does not.
//   refinement  the refinement scenario's room (tests/paint/refine_scenario.h), 60 frames,
//               painted at the true poses (auto must decide off and paint exactly what `off`
//               paints) and at poses with 0.5 degree of rotation noise (auto must decide on
//               and recover most of what `robust` recovers).
//   background  the background test's room with movers going back and forth in front of the
//               walls (decide on) and the same capture without them (decide off).
#include <algorithm>
#include <cstdio>

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "pipeline/paint/auto_modes.h"
#include "pipeline/paint/mover_masks.h"
#include "tests/paint/refine_scenario.h"
#include "tests/paint/room_capture.h"
#include "tests/paint/synth_session.h"

namespace fresco::testing {
namespace {

using State = AutoDecision::State;

PipelineOptions RefineOnly(RefineMode mode) {
  PipelineOptions options;
  options.background.mode = BackgroundMode::kOff;  // refinement alone
  options.refine.mode = mode;
  return options;
}

// Paints the scenario and returns the last frame's decisions.
AutoDecisions Paint(const RefineScenario& scenario, const std::vector<PosedImage>& poses,
                    const PipelineOptions& options, PaintedScenario* painted) {
  AutoDecisions last;
  EXPECT_TRUE(PaintScenario(scenario, poses, options, painted, [&](const FrameReport& r) {
                last = r.decisions;
              }).ok());
  return last;
}

bool SameBuffers(const PaintSession& a, const PaintSession& b) {
  if (a.painted().size() != b.painted().size()) return false;
  for (size_t i = 0; i < a.painted().size(); ++i)
    if (cv::norm(a.painted()[i].bgra, b.painted()[i].bgra, cv::NORM_INF) != 0) return false;
  return true;
}

TEST(AutoRefine, OffOnPerfectPosesOnWithPoseNoise) {
  RefineScenario scenario;
  ASSERT_TRUE(MakeRefineScenario(60, 0.5, &scenario).ok());
  const std::vector<PosedImage>& truth = scenario.capture.true_poses;
  const std::vector<PosedImage>& noisy = scenario.capture.given_poses;

  PaintedScenario off, automatic;
  Paint(scenario, truth, RefineOnly(RefineMode::kOff), &off);
  const AutoDecision perfect =
      Paint(scenario, truth, RefineOnly(RefineMode::kAuto), &automatic).refine;
  std::printf("perfect poses: auto %s\n", perfect.Describe().c_str());
  EXPECT_EQ(perfect.state, State::kOff);
  EXPECT_EQ(perfect.frames_measured, kRefineAutoFrames);
  EXPECT_LT(perfect.evidence, kRefineAutoThresholdPx);
  // Measuring corrects nothing: what auto paints is what off paints, texel for texel.
  EXPECT_TRUE(SameBuffers(*automatic.session, *off.session));

  PaintedScenario noisy_off, noisy_robust, noisy_auto;
  Paint(scenario, noisy, RefineOnly(RefineMode::kOff), &noisy_off);
  Paint(scenario, noisy, RefineOnly(RefineMode::kRobust), &noisy_robust);
  const AutoDecision with_noise =
      Paint(scenario, noisy, RefineOnly(RefineMode::kAuto), &noisy_auto).refine;
  std::printf("0.5 deg of noise: auto %s\n", with_noise.Describe().c_str());
  EXPECT_EQ(with_noise.state, State::kOn);
  EXPECT_GT(with_noise.evidence, 2 * kRefineAutoThresholdPx);
  const double psnr_off = ScenarioPsnr(scenario, noisy_off.scene);
  const double psnr_robust = ScenarioPsnr(scenario, noisy_robust.scene);
  const double psnr_auto = ScenarioPsnr(scenario, noisy_auto.scene);
  const double psnr_perfect = ScenarioPsnr(scenario, off.scene);
  std::printf("truth PSNR: perfect poses %.2f dB; noisy: off %.2f, robust %.2f, auto %.2f dB\n",
              psnr_perfect, psnr_off, psnr_robust, psnr_auto);
  // Auto refines all but its first frames: it keeps most of robust's gain.
  ASSERT_GT(psnr_robust, psnr_off + 1.0);
  EXPECT_GT(psnr_auto - psnr_off, 0.6 * (psnr_robust - psnr_off));
}

// The background test's room with movers (40 frames), or the same without them.
SynthOptions RoomWithMovers(bool movers) {
  SynthOptions o = RoomCaptureWithMovers(40, 0.0);
  if (!movers) o.movers.clear();
  return o;
}

AutoDecision BackgroundDecision(bool movers, GrowMode grow = GrowMode::kAuto) {
  const Scene scene = RoomScene();
  SynthCapture capture;
  EXPECT_TRUE(SynthesizeCapture(scene, RoomWithMovers(movers), &capture).ok());
  PipelineOptions options;
  options.refine.mode = RefineMode::kOff;
  options.background.mode = BackgroundMode::kAuto;
  options.background.grow = grow;
  std::unique_ptr<PaintSession> session = SessionForCapture(scene, capture, options);
  FrameReport report;
  for (size_t i = 0; i < capture.frames_bgr.size(); ++i)
    PaintCaptureFrame(session.get(), capture, i, &report);
  // The options in force show what it resolved to.
  EXPECT_EQ(session->options().background.mode, report.decisions.background.state == State::kOn
                                                    ? BackgroundMode::kRobust
                                                    : BackgroundMode::kOff);
  std::printf("%s: background auto %s\n", movers ? "movers" : "no movers",
              report.decisions.background.Describe().c_str());
  // Dropped: nothing it painted stays provisional (which any later sample would replace,
  // however blurred); every painted texel is kept by its quality, as in `off`.
  if (report.decisions.background.state == State::kOff) {
    int provisional = 0;
    for (const PaintedBuffer& painted : session->painted())
      provisional += cv::countNonZero(painted.quality < 0);
    EXPECT_EQ(provisional, 0);
  }
  return report.decisions.background;
}

TEST(AutoBackground, OnWithMoversOffWithout) {
  const AutoDecision with_movers = BackgroundDecision(true);
  EXPECT_EQ(with_movers.state, State::kOn);
  EXPECT_EQ(with_movers.frames_measured, kBackgroundAutoFrames);
  const AutoDecision without = BackgroundDecision(false);
  EXPECT_EQ(without.state, State::kOff);
  EXPECT_GT(without.frames_measured, kBackgroundAutoFrames);  // movers could still come
  EXPECT_LT(without.evidence, with_movers.evidence / 3);
}

// Captures from files decide before painting, from the movers found across views
// (mover_masks.h): on from the first frame with movers; off without, and then the session
// paints exactly what `off` paints (no model, no warm-up); the decision holds through
// ResetPainting.
AutoDecision DecideAcrossViews(bool movers, bool* paints_as_off) {
  const Scene scene = RoomScene();
  SynthCapture capture;
  EXPECT_TRUE(SynthesizeCapture(scene, RoomWithMovers(movers), &capture).ok());
  const MoverMaskResult found = FindCaptureMovers(scene, capture);
  PipelineOptions options;
  options.refine.mode = RefineMode::kOff;
  options.background.mode = BackgroundMode::kAuto;
  std::unique_ptr<PaintSession> session = SessionForCapture(scene, capture, options);
  session->DecideBackgroundAcrossViews(found.compact_fraction(),
                                       static_cast<int>(found.masks.size()));
  const AutoDecision decided = session->auto_decisions().background;
  std::printf("%s: background auto %s\n", movers ? "movers" : "no movers",
              decided.Describe().c_str());
  session->ResetPainting();
  EXPECT_EQ(session->auto_decisions().background.state, decided.state);
  FrameReport report;
  for (size_t i = 0; i < capture.frames_bgr.size(); ++i)
    PaintCaptureFrame(session.get(), capture, i, &report);
  EXPECT_EQ(report.decisions.background.state, decided.state);
  options.background.mode = BackgroundMode::kOff;
  std::unique_ptr<PaintSession> off = SessionForCapture(scene, capture, options);
  for (size_t i = 0; i < capture.frames_bgr.size(); ++i)
    PaintCaptureFrame(off.get(), capture, i, &report);
  *paints_as_off = SameBuffers(*session, *off);
  return decided;
}

TEST(AutoBackground, CapturesFromFilesDecideBeforePaintingFromMoversAcrossViews) {
  bool as_off = false;
  const AutoDecision with_movers = DecideAcrossViews(true, &as_off);
  EXPECT_EQ(with_movers.state, State::kOn);
  EXPECT_EQ(with_movers.basis, "across_views");
  EXPECT_EQ(with_movers.decided_at_frame, 0);
  EXPECT_EQ(with_movers.frames_measured, 40);
  EXPECT_GT(with_movers.evidence, 2 * kBackgroundAcrossViewsThreshold);
  EXPECT_FALSE(as_off);  // movers masked
  const AutoDecision without = DecideAcrossViews(false, &as_off);
  EXPECT_EQ(without.state, State::kOff);
  EXPECT_LT(without.evidence, kBackgroundAcrossViewsThreshold / 4);
  EXPECT_TRUE(as_off);
}

// Background and update `auto`, refinement off.
PipelineOptions ModelAndUpdateAuto() {
  PipelineOptions options;
  options.refine.mode = RefineMode::kOff;
  options.background.mode = BackgroundMode::kAuto;
  options.update = UpdatePolicy::kAuto;
  return options;
}

// The share of the surface's texels the painted buffers show (alpha > 0).
double PaintedShare(const PaintSession& session) {
  long long painted = 0, surface = 0;
  for (size_t b = 0; b < session.buffers().size(); ++b) {
    const BaseBuffer& buffer = session.buffers()[b];
    const cv::Mat& bgra = session.painted()[b].bgra;
    for (size_t k = 0; k < buffer.texel_index.size(); ++k) {
      if (!buffer.on_surface[k]) continue;
      ++surface;
      painted += bgra.ptr<cv::Vec4b>()[buffer.texel_index[k]][3] > 0;
    }
  }
  return surface > 0 ? static_cast<double>(painted) / surface : 0.0;
}

// With the model on and the mean chosen, the coverage counts what the mean paints: the texels
// the model kept out of the sharpest view too.
TEST(AutoBackground, TheMeanChosenWithTheModelOnCountsEveryTexelItPaints) {
  const Scene scene = RoomScene();
  SynthCapture capture;
  ASSERT_TRUE(SynthesizeCapture(scene, RoomWithMovers(true), &capture).ok());
  PipelineOptions options = ModelAndUpdateAuto();
  std::unique_ptr<PaintSession> session = SessionForCapture(scene, capture, options);
  session->DecideBackgroundAcrossViews(4 * kBackgroundAcrossViewsThreshold, 40);
  FrameReport report;
  for (size_t i = 0; i < capture.frames_bgr.size(); ++i)
    PaintCaptureFrame(session.get(), capture, i, &report);
  std::printf("update %s; coverage %.6f, painted %.6f\n",
              session->auto_decisions().update.Describe().c_str(), session->Coverage(),
              PaintedShare(*session));
  ASSERT_EQ(session->auto_decisions().update.state, State::kOn);
  EXPECT_DOUBLE_EQ(session->Coverage(), PaintedShare(*session));
}

// Where the movers found across views turned the model on but the capture has none, the frames
// held out of `update: auto` turn it off on their first half (kModelHeldOutFrames), not at the
// update's decision near the end: what the model would cost for the rest is saved, and the mean
// painted is the one a session without the model paints.
TEST(AutoBackground, FramesHeldOutTurnAModelWithoutMoversOffOnTheirFirstHalf) {
  const Scene scene = RoomScene();
  SynthCapture capture;
  SynthOptions o = RoomCaptureWithMovers(40, 0.1);  // exposure changes, no movers
  o.movers.clear();
  ASSERT_TRUE(SynthesizeCapture(scene, o, &capture).ok());
  PipelineOptions options = ModelAndUpdateAuto();
  std::unique_ptr<PaintSession> session = SessionForCapture(scene, capture, options);
  session->DecideBackgroundAcrossViews(4 * kBackgroundAcrossViewsThreshold, 40);  // fooled
  ASSERT_EQ(session->auto_decisions().background.state, State::kOn);
  FrameReport report;
  int model_off_at = -1;
  for (size_t i = 0; i < capture.frames_bgr.size(); ++i) {
    PaintCaptureFrame(session.get(), capture, i, &report);
    if (model_off_at < 0 && report.decisions.background.state == State::kOff)
      model_off_at = static_cast<int>(i) + 1;
  }
  const AutoDecision model = session->auto_decisions().background;
  const AutoDecision update = session->auto_decisions().update;
  std::printf("background %s; update %s\n", model.Describe().c_str(), update.Describe().c_str());
  EXPECT_EQ(model.state, State::kOff);
  EXPECT_EQ(model.basis, "held_out_without_model");
  EXPECT_EQ(model.frames_measured, PaintSession::kModelHeldOutFrames);
  // Held out every 40 / 7 = 5th frame: the third is frame 12, the decision after frame 15.
  EXPECT_EQ(model_off_at, 15);
  EXPECT_EQ(model.decided_at_frame, 15);
  EXPECT_GT(model.evidence, 0);
  EXPECT_EQ(update.state, State::kOn);  // the mean
  EXPECT_EQ(update.frames_measured, 6);
  options.background.mode = BackgroundMode::kOff;
  std::unique_ptr<PaintSession> off = SessionForCapture(scene, capture, options);
  for (size_t i = 0; i < capture.frames_bgr.size(); ++i)
    PaintCaptureFrame(off.get(), capture, i, &report);
  EXPECT_EQ(off->auto_decisions().update.state, State::kOn);
  EXPECT_DOUBLE_EQ(session->Coverage(), PaintedShare(*session));
  for (size_t b = 0; b < off->painted().size(); ++b)
    EXPECT_LE(cv::norm(session->painted()[b].bgra, off->painted()[b].bgra, cv::NORM_INF), 1.0)
        << "buffer " << b;
}

// The evidence is the model's own verdict (its cleaned mask), not the mask grown by colour:
// growth spreads whatever was flagged, e.g. over a uniform road from the few texels of a
// high-frequency pavement that a closer view flags, and would decide a static scene on.
TEST(AutoBackground, GrowthIsNoEvidence) {
  const AutoDecision grown = BackgroundDecision(true, GrowMode::kOn);
  const AutoDecision ungrown = BackgroundDecision(true, GrowMode::kOff);
  EXPECT_EQ(grown.state, State::kOn);
  EXPECT_EQ(grown.frames_measured, ungrown.frames_measured);
  EXPECT_DOUBLE_EQ(grown.evidence, ungrown.evidence);
}

// The evidence is the misalignment a pose correction removes, not the residual: movers and
// exposure changes leave a residual at exact poses that no correction explains, while a few
// centimetres of camera-centre noise (no rotation noise) is explained by one. `pose_check`
// >= 0: the joint pose adjustment's check ratio the session is given before painting.
AutoDecision RefineDecision(double exposure_jitter, double pose_noise_m, double* residual_px,
                            double pose_check = -1) {
  const Scene scene = RoomScene();
  SynthOptions o = RoomCaptureWithMovers(20, exposure_jitter);
  o.pose_noise_m = pose_noise_m;
  SynthCapture capture;
  EXPECT_TRUE(SynthesizeCapture(scene, o, &capture).ok());
  PipelineOptions options;
  options.refine.mode = RefineMode::kAuto;
  options.background.mode = BackgroundMode::kRobust;
  std::unique_ptr<PaintSession> session = SessionForCapture(scene, capture, options);
  if (pose_check >= 0) session->SetRefinePoseCheck(pose_check, 1.1, 20);
  FrameReport report;
  std::vector<double> residuals;
  for (size_t i = 0; i < capture.frames_bgr.size(); ++i) {
    Frame frame;
    frame.index = static_cast<int>(i);
    frame.bgr = capture.frames_bgr[i];
    session->PaintFrame(frame, capture.camera, capture.given_poses[i].cam_from_world, &report);
    const StageReport* refine = report.Stage("refine");
    if (refine && refine->metrics.count("pose_inliers") && refine->metrics.at("pose_inliers") > 0 &&
        report.decisions.refine.decided_at_frame < 0)
      residuals.push_back(refine->metrics.at("pose_residual_before_px"));
  }
  std::sort(residuals.begin(), residuals.end());
  *residual_px = residuals.empty() ? -1 : residuals[residuals.size() / 2];
  std::printf("exposure jitter %.2f, centre noise %.2f m: residual %.2f texels, auto %s\n",
              exposure_jitter, pose_noise_m, *residual_px,
              report.decisions.refine.Describe().c_str());
  return report.decisions.refine;
}

TEST(AutoRefine, MoversAndExposureAreNotTakenForPoseErrorCentreNoiseIs) {
  double residual = 0;
  const AutoDecision exact = RefineDecision(0.15, 0.0, &residual);
  EXPECT_EQ(exact.state, State::kOff);
  EXPECT_LT(exact.evidence, 0.1);
  // The scenario holds the trap: its residual alone (measured 0.77 texels) is above what the
  // residual rule took for pose error (0.6).
  EXPECT_GT(residual, 0.6);
  const AutoDecision noisy = RefineDecision(0.15, 0.01, &residual);
  EXPECT_EQ(noisy.state, State::kOn);
  EXPECT_GT(noisy.evidence, 2 * kRefineAutoThresholdPx);
}

// The joint pose adjustment's check on frames left out of its corrections vetoes `on`: where
// they do not agree 1.1 times better with the corrected frames (a mesh's error, exact poses),
// misalignment measured on the first frames does not switch a per-frame correction on; where
// they do, it decides as before.
TEST(AutoRefine, APoseCheckThatFramesLeftOutFailKeepsItOff) {
  double residual = 0;
  const AutoDecision vetoed = RefineDecision(0.15, 0.01, &residual, 0.87);
  EXPECT_EQ(vetoed.state, State::kOff);
  EXPECT_EQ(vetoed.basis, "held_out_poses");
  EXPECT_DOUBLE_EQ(vetoed.evidence, 0.87);
  EXPECT_DOUBLE_EQ(vetoed.threshold, 1.1);
  EXPECT_EQ(vetoed.frames_measured, 20);
  EXPECT_GT(vetoed.decided_at_frame, 0);
  const AutoDecision passed = RefineDecision(0.15, 0.01, &residual, 1.4);
  EXPECT_EQ(passed.state, State::kOn);
  EXPECT_EQ(passed.basis, "");
  EXPECT_GT(passed.evidence, 2 * kRefineAutoThresholdPx);
  // Measured below the threshold: off as before, on the misalignment.
  RefineAutoDecider aligned;
  aligned.SetPoseCheck(0.87, 1.1, 20);
  aligned.Start(true);  // the check is kept through Start
  for (int f = 1; f <= kRefineAutoFrames; ++f) aligned.AddFrame(f, 0.05);
  EXPECT_EQ(aligned.decision().state, State::kOff);
  EXPECT_EQ(aligned.decision().basis, "");
  RefineAutoDecider misaligned;
  misaligned.SetPoseCheck(0.87, 1.1, 20);
  misaligned.Start(true);
  for (int f = 1; f <= kRefineAutoFrames; ++f) misaligned.AddFrame(f, 0.6);
  EXPECT_EQ(misaligned.decision().state, State::kOff);
  EXPECT_EQ(misaligned.decision().Describe(),
            "off: the first frames look misaligned, but frames left out of the pose corrections "
            "agree 0.87 times better with the corrected frames (1.10 needed; 20 frames; decided "
            "at frame 6)");
}

TEST(AutoRefine, FramesThatCannotBeRegisteredDecideOffEarly) {
  RefineAutoDecider decider;
  decider.Start(true);
  for (int f = 1; f < kRefineAutoNoEvidenceFrame; ++f) EXPECT_FALSE(decider.AddFrame(f, -1));
  EXPECT_TRUE(decider.AddFrame(kRefineAutoNoEvidenceFrame, -1));
  EXPECT_EQ(decider.decision().state, State::kOff);
  EXPECT_EQ(decider.decision().frames_measured, 0);
  // One measurement early on keeps it deciding to the usual count.
  RefineAutoDecider measured;
  measured.Start(true);
  EXPECT_FALSE(measured.AddFrame(1, 2.0));
  for (int f = 2; f <= kRefineAutoNoEvidenceFrame + 1; ++f) EXPECT_FALSE(measured.AddFrame(f, -1));
  EXPECT_EQ(measured.decision().state, State::kDeciding);
}

TEST(AutoDecisionReport, ShowsEvidenceAndThreshold) {
  RefineAutoDecider decider;
  decider.Start(true);
  for (int f = 1; f < kRefineAutoFrames; ++f) EXPECT_FALSE(decider.AddFrame(f, 2.0));
  EXPECT_FALSE(decider.AddFrame(kRefineAutoFrames, -1));  // no measurement: not counted
  EXPECT_EQ(decider.decision().state, State::kDeciding);
  EXPECT_TRUE(decider.AddFrame(kRefineAutoFrames + 1, 0.1));
  EXPECT_EQ(decider.decision().state, State::kOn);  // median of five 2.0 and one 0.1
  EXPECT_DOUBLE_EQ(decider.decision().evidence, 2.0);
  StageReport stage;
  decider.decision().PutInto(&stage);
  EXPECT_EQ(stage.metrics.at("auto_decision"), 1.0);
  EXPECT_EQ(stage.metrics.at("auto_threshold"), kRefineAutoThresholdPx);
  EXPECT_EQ(stage.notes.at("auto"), "on: 2 > 0.25 over 6 frames (decided at frame 7)");
  const std::string json = AutoDecisionsJson({decider.decision(), AutoDecision()});
  EXPECT_NE(json.find("\"decision\":\"on\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"background\":null"), std::string::npos) << json;
}

}  // namespace
}  // namespace fresco::testing
