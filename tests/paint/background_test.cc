// Selective painting (paper §3.4) against ground truth.
// Synthetic: a hand-held capture inside the room with moving spheres and boxes. For every
// frame the test knows which pixels show a mover (the movers' triangle ids), warps that
// mask into the base buffers like the frame, and follows which texels each frame writes
// (MoverProvenance, as `fresco eval` does): at the end it knows, for every painted texel,
// whether its colour came from a mover.
// Real: two static-camera clips (Intel IoT devkit sample videos, CC BY 4.0) painted onto a
// plane filling the view, so the painted buffer is the learned background image; it is
// scored against the clips' empty frames with the background-estimation metrics AGE, pEPs
// and PSNR (grey levels).
#include <cmath>
#include <cstdio>
#include <map>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/video_source.h"
#include "pipeline/eval/mover_provenance.h"
#include "pipeline/paint/mover_masks.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/render/renderer.h"
#include "pipeline/synth/procedural_scenes.h"
#include "pipeline/synth/synthesize.h"
#include "tests/paint/room_capture.h"
#include "tests/paint/synth_session.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

// ---- Synthetic captures with movers. ---------------------------------------------------------

Scene Room() { return testing::RoomScene(); }

// The room with movers over `frames` frames, steady exposure.
SynthCapture SteadyRoomWithMovers(const Scene& scene, int frames) {
  SynthCapture capture;
  EXPECT_TRUE(SynthesizeCapture(scene, testing::RoomCaptureWithMovers(frames, 0.0), &capture).ok());
  return capture;
}

// The robust background model alone: refinement off (exact poses).
PipelineOptions RobustWithoutRefinement() {
  PipelineOptions options;
  options.refine.mode = RefineMode::kOff;
  options.background.mode = BackgroundMode::kRobust;
  return options;
}

struct MoverFigures : MoverProvenance::Figures {
  double masked_fraction = 0;  // mean of the background stage's masked_fraction
  long long near_movers = 0;   // sum of the background stage's texels_near_movers
};

// Paints the capture (true poses) and follows which painted texels took a mover's colour.
// `movers`: each frame's movers found across views (Frame::movers), or null.
MoverFigures PaintWithMovers(const Scene& scene, const SynthCapture& capture,
                             const PipelineOptions& options,
                             const std::vector<cv::Mat>* movers = nullptr) {
  std::unique_ptr<PaintSession> session = testing::SessionForCapture(scene, capture, options);
  MoverProvenance provenance(scene, capture.movers, scene, capture.camera, *session);
  MoverFigures figures;
  FrameReport report;
  for (size_t i = 0; i < capture.frames_bgr.size(); ++i) {
    const Rigid3d& cam_from_world = capture.true_poses[i].cam_from_world;
    provenance.BeforeFrame(*session);
    Frame frame;
    frame.index = static_cast<int>(i);
    frame.bgr = capture.frames_bgr[i];
    if (movers) frame.movers = (*movers)[i];
    session->PaintFrame(frame, capture.camera, cam_from_world, &report);
    if (const StageReport* stage = report.Stage("background")) {
      figures.masked_fraction += stage->metrics.at("masked_fraction") / capture.frames_bgr.size();
      figures.near_movers += static_cast<long long>(stage->metrics.at("texels_near_movers"));
    }
    provenance.AfterFrame(*session, static_cast<int>(i), cam_from_world, cam_from_world);
  }
  static_cast<MoverProvenance::Figures&>(figures) = provenance.Count(*session);
  return figures;
}

void Print(const char* name, const MoverFigures& f) {
  std::printf(
      "%-8s mover texels painted %6.3f %% (%lld of %lld), open texels painted %6.2f %%, "
      "masked %5.2f %% per frame, dominated %lld\n",
      name, 100 * f.mover_fraction(), f.painted_mover, f.painted, 100 * f.open_coverage(),
      100 * f.masked_fraction, f.mover_dominated);
  std::printf(
      "         painted from a mover: %lld never seen without one, %lld every sample without "
      "one kept out, %lld one not taken, %lld one painted and replaced\n",
      f.mover_never_open, f.mover_open_masked, f.mover_open_passed, f.mover_open_replaced);
}

class MoversTest : public ::testing::TestWithParam<double> {};

TEST_P(MoversTest, RobustModelPaintsAlmostNoMoverAndKeepsTheStaticScene) {
  const double exposure_jitter = GetParam();
  const Scene scene = Room();
  SynthCapture capture;
  ASSERT_TRUE(
      SynthesizeCapture(scene, testing::RoomCaptureWithMovers(150, exposure_jitter), &capture)
          .ok());
  ASSERT_GE(capture.movers.size(), 3u);
  PipelineOptions options;
  options.refine.mode = RefineMode::kOff;  // perfect poses: the background models alone
  std::map<BackgroundMode, MoverFigures> figures;
  for (BackgroundMode mode :
       {BackgroundMode::kOff, BackgroundMode::kAverage, BackgroundMode::kRobust}) {
    options.background.mode = mode;
    // The baseline that shows the movers: no background model and no view selection (which
    // keeps out some mover samples on its own: 1.9 % of texels instead of 2.x).
    options.select.enabled = mode != BackgroundMode::kOff;
    figures[mode] = PaintWithMovers(scene, capture, options);
    Print(BackgroundModeName(mode).c_str(), figures[mode]);
  }
  const MoverFigures& off = figures[BackgroundMode::kOff];
  const MoverFigures& robust = figures[BackgroundMode::kRobust];
  // The movers are there: without background learning they are painted on the walls.
  EXPECT_GT(off.mover_fraction(), 0.02);
  EXPECT_LT(robust.mover_fraction(), 0.005);
  EXPECT_LT(robust.mover_fraction(), off.mover_fraction() / 10);
  // What was ever seen without a mover on it is painted (nearly) as without movers.
  EXPECT_GE(robust.open_coverage(), 0.99 * off.open_coverage());
  // Why the movers are painted: without a model no sample is kept out of painting.
  EXPECT_EQ(off.mover_open_masked, 0);
  EXPECT_GT(off.mover_open_passed + off.mover_open_replaced, 0);
}

// The mean of every view rewrites a texel with each sample, so which sample came last says
// nothing: a texel shows a mover where movers are a quarter or more of the samples it
// averages (MoverProvenance::ShowsMover). In this room the movers linger: the mean shows
// them on more texels than the sharpest view does (measured 7.8 % against 3.9 %), the robust
// model keeps half of that out (3.9 %), and `auto` (update and background) paints fewer
// (1.4 %).
TEST(MoverProvenance, TheMeanShowsAMoverWhereMoversAreAQuarterOfItsSamples) {
  const Scene scene = Room();
  const SynthCapture capture = SteadyRoomWithMovers(scene, 100);
  PipelineOptions options;
  options.refine.mode = RefineMode::kOff;
  options.select.enabled = false;
  options.background.mode = BackgroundMode::kOff;
  options.update = UpdatePolicy::kQuality;
  const MoverFigures sharpest = PaintWithMovers(scene, capture, options);
  options.update = UpdatePolicy::kMean;
  const MoverFigures mean = PaintWithMovers(scene, capture, options);
  options.background.mode = BackgroundMode::kRobust;
  const MoverFigures robust_mean = PaintWithMovers(scene, capture, options);
  Print("sharpest", sharpest);
  Print("mean", mean);
  Print("robust", robust_mean);
  options.update = UpdatePolicy::kAuto;
  options.background.mode = BackgroundMode::kAuto;
  const MoverFigures automatic = PaintWithMovers(scene, capture, options);
  Print("auto", automatic);
  EXPECT_LT(automatic.mover_fraction(), 0.6 * robust_mean.mover_fraction());
  EXPECT_GT(mean.mover_fraction(), 1.5 * sharpest.mover_fraction());
  EXPECT_LT(robust_mean.mover_fraction(), 0.6 * mean.mover_fraction());
  EXPECT_GT(robust_mean.mover_fraction(), 0.0);
}

// What the session reports it kept out of painting (PaintSession::KeptOutOfPainting, which
// `fresco eval` splits the painted movers by) is what the paint stage left alone: no texel it
// names is written that frame, and the robust model does keep movers out.
TEST(KeptOutOfPainting, IsWhatThePaintStageLeftAlone) {
  const Scene scene = Room();
  const SynthCapture capture = SteadyRoomWithMovers(scene, 40);
  std::unique_ptr<PaintSession> session =
      testing::SessionForCapture(scene, capture, RobustWithoutRefinement());
  FrameReport report;
  long long kept_out = 0, kept_out_written = 0, written = 0;
  for (size_t i = 0; i < capture.frames_bgr.size(); ++i) {
    std::vector<cv::Mat> before;
    for (const PaintedBuffer& p : session->painted()) before.push_back(p.bgra.clone());
    Frame frame;
    frame.index = static_cast<int>(i);
    frame.bgr = capture.frames_bgr[i];
    session->PaintFrame(frame, capture.camera, capture.true_poses[i].cam_from_world, &report);
    for (size_t b = 0; b < before.size(); ++b) {
      cv::Mat diff, changed;
      cv::absdiff(before[b], session->painted()[b].bgra, diff);
      cv::transform(diff, changed, cv::Matx14f(1, 1, 1, 1));
      changed = changed > 0;
      written += cv::countNonZero(changed);
      const cv::Mat out = session->KeptOutOfPainting(b);
      if (out.empty()) continue;
      kept_out += cv::countNonZero(out);
      kept_out_written += cv::countNonZero(out & changed);
    }
  }
  EXPECT_GT(written, 0);
  EXPECT_GT(kept_out, 0);
  EXPECT_EQ(kept_out_written, 0);
}

// The room with movers (`frames` of them, exact poses) painted by the robust model with
// refinement off and growth `grow`: without the movers found across views, and with them.
struct AloneAndWithMasks {
  MoverFigures alone, with_masks;
};
// The robust model with refinement off (exact poses) and growth `grow`, with the masks found
// across views alone: no margin around them (that is TheMarginPaintsLessOfTheMovers').
PipelineOptions MasksAlone(GrowMode grow) {
  PipelineOptions options = RobustWithoutRefinement();
  options.background.grow = grow;
  options.background.mover_margin = 0;
  return options;
}

// Each frame's masks and agreed pixels in one image (MoverMaskResult::Packed).
std::vector<cv::Mat> PackedMasks(const MoverMaskResult& found) {
  std::vector<cv::Mat> packed;
  for (size_t k = 0; k < found.masks.size(); ++k) packed.push_back(found.Packed(k));
  return packed;
}

AloneAndWithMasks PaintAloneAndWithMasks(int frames, GrowMode grow,
                                         const MoverMaskOptions& mask_options = {}) {
  const Scene scene = Room();
  SynthCapture capture;
  EXPECT_TRUE(SynthesizeCapture(scene, testing::RoomCaptureWithMovers(frames, 0.0), &capture).ok());
  const MoverMaskResult found = testing::FindCaptureMovers(scene, capture, mask_options);
  EXPECT_GT(found.fraction(), 0.0);
  const PipelineOptions options = MasksAlone(grow);
  AloneAndWithMasks out;
  out.alone = PaintWithMovers(scene, capture, options);
  out.with_masks = PaintWithMovers(scene, capture, options, &found.masks);
  Print("alone", out.alone);
  Print("masks", out.with_masks);
  return out;
}

// The movers found across views (mover_masks.h) that touch what the robust model flags join
// its foreground (where it grows): less of the movers is painted, and nothing seen without
// one is lost.
TEST(MoversAcrossViews, JoinTheForegroundTheyTouch) {
  // The join comes with growth (refinement is off: on by hand). The masks as the comparison
  // across views finds them: following them by their colours (mover_follow.h) lowers the leak
  // on the evaluation suites, but here paints 95 of these texels instead of 58 (of 704,800).
  MoverMaskOptions mask_options;
  mask_options.follow_frames = 0;
  const AloneAndWithMasks f = PaintAloneAndWithMasks(150, GrowMode::kOn, mask_options);
  EXPECT_LT(f.with_masks.mover_fraction(), 0.8 * f.alone.mover_fraction());
  EXPECT_GE(f.with_masks.open_coverage(), 0.99 * f.alone.open_coverage());
}

// Where a mover the model learned as background has gone, the model flags the background
// itself (a ghost), and growth from there covers the surface around it of that colour. The
// frames near each frame agree with what its pixels show there (MoverMaskResult::agreed):
// growth does not start from those texels, and more of what was seen without a mover is
// painted, no more of the movers (on the evaluation suite's streets 85.9 -> 91.7 % and
// 90.5 -> 91.9 % of it).
TEST(MoversAcrossViews, GrowthDoesNotStartWhereTheFramesAgree) {
  const Scene scene = Room();
  SynthCapture capture;
  ASSERT_TRUE(SynthesizeCapture(scene, testing::RoomCaptureWithMovers(150, 0.0), &capture).ok());
  // The masks as measured when this was built: here the regions the masks ring, followed into
  // the frames next to them, leave fewer agreed pixels to make the difference (0.26 -> 0.24 %).
  MoverMaskOptions mask_options;
  mask_options.ringed_follow_frames = 0;
  const MoverMaskResult found = testing::FindCaptureMovers(scene, capture, mask_options);
  const std::vector<cv::Mat> packed = PackedMasks(found);
  for (size_t k = 0; k < found.masks.size(); ++k)
    ASSERT_EQ(cv::countNonZero(packed[k] == kMoverPixel), cv::countNonZero(found.masks[k]));
  const PipelineOptions options = MasksAlone(GrowMode::kOn);
  const MoverFigures masks = PaintWithMovers(scene, capture, options, &found.masks);
  const MoverFigures agreed = PaintWithMovers(scene, capture, options, &packed);
  Print("masks", masks);
  Print("agreed", agreed);
  // Of what was seen without a mover, 0.15 % left unpainted -> 0.10 %; mover texels 77 -> 76.
  EXPECT_LT(1 - agreed.open_coverage(), 0.8 * (1 - masks.open_coverage()));
  EXPECT_LE(agreed.painted_mover, masks.painted_mover);
}

// Without growth the masks neither join nor keep anything out: kept out on their own they
// painted more of this room's movers (0.19 -> 0.26-0.30 % of the texels), as the background
// beside a mover, masked for what a neighbouring frame showed, is what replaces it later.
TEST(MoversAcrossViews, ChangeNothingWithoutGrowth) {
  const AloneAndWithMasks f = PaintAloneAndWithMasks(60, GrowMode::kOff);
  EXPECT_EQ(f.with_masks.painted, f.alone.painted);
  EXPECT_EQ(f.with_masks.painted_mover, f.alone.painted_mover);
}

// Masks over the middle third of each frame of `capture`.
std::vector<cv::Mat> MiddleThirdMasks(const SynthCapture& capture) {
  const cv::Size size(capture.camera.width, capture.camera.height);
  std::vector<cv::Mat> masks(capture.true_poses.size());
  for (cv::Mat& m : masks) {
    m = cv::Mat::zeros(size, CV_8U);
    m(cv::Rect(size.width / 3, 0, size.width / 3, size.height)).setTo(255);
  }
  return masks;
}

// The robust model with refinement and growth `auto` (growth waits for refinement).
PipelineOptions RobustWithAutoRefinement() {
  PipelineOptions options;
  options.refine.mode = RefineMode::kAuto;
  options.background.mode = BackgroundMode::kRobust;
  options.background.grow = GrowMode::kAuto;
  return options;
}

// In the first two frames refinement's `auto` has nothing to measure yet, and growth waits
// for it; the movers found across views are kept out of painting there all the same (the
// first frames' movers are the ones that stay). Masks over the middle third of each frame.
TEST(MoversAcrossViews, KeptOutOfTheFirstFramesWhileRefinementDecides) {
  const Scene scene = Room();
  SynthCapture capture;
  ASSERT_TRUE(SynthesizeCapture(scene, testing::RoomCaptureWithMovers(2, 0.0), &capture).ok());
  const std::vector<cv::Mat> masks = MiddleThirdMasks(capture);
  const PipelineOptions options = RobustWithAutoRefinement();
  const MoverFigures alone = PaintWithMovers(scene, capture, options);
  const MoverFigures with_masks = PaintWithMovers(scene, capture, options, &masks);
  Print("alone", alone);
  Print("masks", with_masks);
  EXPECT_GT(alone.painted, 0);
  EXPECT_LT(with_masks.painted, 0.8 * alone.painted);
}

// The pixels around the movers found (background.mover_margin, a share of the frame's longer
// side) are kept out of painting too: with masks over the middle third of two frames, a
// margin of 5 % of the width leaves out that much more of the frame on each side of them.
TEST(MoversAcrossViews, TheMarginAroundThemIsNotPainted) {
  const Scene scene = Room();
  SynthCapture capture;
  ASSERT_TRUE(SynthesizeCapture(scene, testing::RoomCaptureWithMovers(2, 0.0), &capture).ok());
  const std::vector<cv::Mat> masks = MiddleThirdMasks(capture);
  PipelineOptions options = RobustWithAutoRefinement();
  options.background.mover_margin = 0;
  const MoverFigures none = PaintWithMovers(scene, capture, options, &masks);
  options.background.mover_margin = 0.05;
  const MoverFigures margin = PaintWithMovers(scene, capture, options, &masks);
  Print("no margin", none);
  Print("margin", margin);
  // Two thirds of the width painted without the margin, a little over half with it; the
  // background stage reports the texels it kept out for the margin alone.
  EXPECT_LT(margin.painted, 0.92 * none.painted);
  EXPECT_GT(margin.painted, 0.7 * none.painted);
  EXPECT_EQ(none.near_movers, 0);
  EXPECT_GT(margin.near_movers, 0);
}

// On the room with movers, the margin paints less of the movers.
TEST(MoversAcrossViews, TheMarginPaintsLessOfTheMovers) {
  const Scene scene = Room();
  SynthCapture capture;
  ASSERT_TRUE(SynthesizeCapture(scene, testing::RoomCaptureWithMovers(150, 0.0), &capture).ok());
  const std::vector<cv::Mat> packed = PackedMasks(testing::FindCaptureMovers(scene, capture, {}));
  PipelineOptions options = MasksAlone(GrowMode::kOn);
  const MoverFigures none = PaintWithMovers(scene, capture, options, &packed);
  options.background.mover_margin = BackgroundOptions().mover_margin;
  const MoverFigures margin = PaintWithMovers(scene, capture, options, &packed);
  Print("no margin", none);
  Print("margin", margin);
  EXPECT_LT(margin.painted_mover, none.painted_mover);
  EXPECT_GE(margin.open_coverage(), 0.99 * none.open_coverage());
}

INSTANTIATE_TEST_SUITE_P(Exposure, MoversTest, ::testing::Values(0.0, 0.08), [](const auto& info) {
  return info.param == 0.0 ? std::string("Steady") : std::string("Jitter");
});

// Several streams painting one model: each stream's frames are classified against its own
// background models, so a camera that sees the surface differently (here the same frames,
// half as bright, as a second stream) neither teaches nor is judged by another's model.
TEST(StreamBackground, EachStreamLearnsOnlyFromItsOwnFrames) {
  const Scene scene = Room();
  const SynthCapture capture = SteadyRoomWithMovers(scene, 12);
  PipelineOptions options = RobustWithoutRefinement();
  options.select.enabled = false;  // the exposure stage would adapt frames to the buffers
  std::unique_ptr<PaintSession> alone = testing::SessionForCapture(scene, capture, options);
  std::unique_ptr<PaintSession> both = testing::SessionForCapture(scene, capture, options);
  ASSERT_TRUE(alone && both);
  const size_t nb = both->buffers().size();
  for (size_t b = 0; b < nb; ++b) EXPECT_TRUE(both->BackgroundImage(b, 1).empty());
  FrameReport report;
  for (size_t i = 0; i < capture.frames_bgr.size(); ++i) {
    const Rigid3d& cam_from_world = capture.true_poses[i].cam_from_world;
    testing::PaintCaptureFrame(alone.get(), capture, i, &report);
    Frame frame;
    frame.index = static_cast<int>(i);
    frame.bgr = capture.frames_bgr[i];
    both->PaintFrame(frame, capture.camera, cam_from_world, 0, &report);
    frame.bgr = capture.frames_bgr[i] * 0.5;
    both->PaintFrame(frame, capture.camera, cam_from_world, 1, &report);
  }
  // Stream 0's models are what they are without stream 1, bit for bit; stream 1's learned
  // its own, darker frames.
  double mean0 = 0, mean1 = 0;
  for (size_t b = 0; b < nb; ++b) {
    const cv::Mat model = alone->BackgroundImage(b);
    const cv::Mat model0 = both->BackgroundImage(b, 0), model1 = both->BackgroundImage(b, 1);
    ASSERT_EQ(model0.size(), model.size());
    ASSERT_EQ(model1.size(), model.size());
    EXPECT_EQ(cv::norm(model0, model, cv::NORM_INF), 0.0) << "buffer " << b;
    mean0 += cv::sum(model0)[0] + cv::sum(model0)[1] + cv::sum(model0)[2];
    mean1 += cv::sum(model1)[0] + cv::sum(model1)[1] + cv::sum(model1)[2];
  }
  EXPECT_TRUE(both->BackgroundImage(0, 2).empty());
  EXPECT_GT(mean0, 0);
  EXPECT_NEAR(mean1 / mean0, 0.5, 0.05);
}

// ---- Real static-camera video. ---------------------------------------------------------------

// The static-camera projects: a plane at 5 m filling the view of a 768 x 432 pinhole
// camera (f = 500 px) looking at it head-on, one texel (1 cm) per pixel.
constexpr double kPlaneDistanceM = 5.0;
constexpr double kFocalPx = 500.0;

struct BackgroundScore {
  double age = 0;      // mean absolute grey difference
  double peps = 0;     // fraction of pixels off by more than 20 grey levels
  double psnr_db = 0;  // grey PSNR
};

BackgroundScore Score(const cv::Mat& estimate_grey, const cv::Mat& truth_grey) {
  cv::Mat diff;
  cv::absdiff(estimate_grey, truth_grey, diff);
  BackgroundScore s;
  s.age = cv::mean(diff)[0];
  s.peps = static_cast<double>(cv::countNonZero(diff > 20)) / diff.total();
  cv::Mat d;
  diff.convertTo(d, CV_64F);
  const double mse = cv::mean(d.mul(d))[0];
  s.psnr_db = 10 * std::log10(255.0 * 255.0 / std::max(mse, 1e-10));
  return s;
}

// Paints a clip onto the plane once per mode in `modes` (the clip decoded once, each frame
// painted by every mode's session); returns each mode's painted plane rendered through the
// camera (grey) and keeps the grey frames listed in `keep`.
std::map<BackgroundMode, cv::Mat> LearnBackgrounds(const std::string& video,
                                                   const std::vector<BackgroundMode>& modes,
                                                   const std::vector<int>& keep,
                                                   std::map<int, cv::Mat>* kept) {
  std::map<BackgroundMode, cv::Mat> learned;
  std::unique_ptr<VideoSource> source;
  EXPECT_TRUE(OpenVideoSource(video, &source).ok()) << video;
  if (!source) return learned;
  Frame frame;
  Status status;
  EXPECT_TRUE(source->Next(&frame, &status)) << video;
  const int w = frame.bgr.cols, h = frame.bgr.rows;
  const Camera camera = Camera::FromParams(LensModel::kPinhole, w, h,
                                           {kFocalPx, kFocalPx, 0.5 * (w - 1), 0.5 * (h - 1)});
  const double s = kPlaneDistanceM / kFocalPx;
  const Scene scene = MakeTexturedPlaneScene(w * s, h * s);
  // At z = 5 m looking towards -Z (at the plane's front), image y down = world -Y.
  const Rigid3d cam_from_world(
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX())),
      Eigen::Vector3d(0, 0, kPlaneDistanceM));
  std::map<BackgroundMode, std::unique_ptr<PaintSession>> sessions;
  for (BackgroundMode mode : modes) {
    PaintSessionInputs inputs;
    inputs.scene = &scene;
    inputs.pipeline.texel_size_m = s;
    inputs.pipeline.background.mode = mode;
    inputs.pipeline.refine.mode = RefineMode::kOff;  // a static camera: nothing to align
    EXPECT_TRUE(PaintSession::Create(inputs, &sessions[mode]).ok());
    if (!sessions[mode]) return learned;
  }
  FrameReport report;
  do {
    for (int k : keep)
      if (frame.index == k) cv::cvtColor(frame.bgr, (*kept)[k], cv::COLOR_BGR2GRAY);
    for (auto& [mode, session] : sessions)
      session->PaintFrame(frame, camera, cam_from_world, &report);
  } while (source->Next(&frame, &status));
  EXPECT_TRUE(status.ok()) << status.message();
  RenderOptions render_options;
  render_options.filter = TextureFilter::kNearest;
  const Renderer renderer(camera, render_options);
  for (auto& [mode, session] : sessions) {
    RenderOutput out;
    renderer.Render(session->PaintedScene(), cam_from_world, &out);
    cv::cvtColor(out.rgba, learned[mode], cv::COLOR_RGBA2GRAY);
  }
  return learned;
}

struct ClipCase {
  const char* file;
  std::vector<int> empty_frames;  // frames that show the empty scene (the ground truth)
};

// Scores each model's learned background against the clip's empty frames. Returns the mean
// score per mode and prints a table.
std::map<BackgroundMode, BackgroundScore> ScoreClip(const ClipCase& clip) {
  const std::string video = testing::SharedDataDir() + "/video-intel-static-cam/" + clip.file;
  std::map<BackgroundMode, BackgroundScore> result;
  std::map<int, cv::Mat> truth;
  const std::vector<BackgroundMode> modes = {BackgroundMode::kOff, BackgroundMode::kAverage,
                                             BackgroundMode::kRobust};
  std::map<BackgroundMode, cv::Mat> learned =
      LearnBackgrounds(video, modes, clip.empty_frames, &truth);
  for (BackgroundMode mode : modes) {
    const cv::Mat& estimate = learned[mode];
    EXPECT_FALSE(estimate.empty()) << BackgroundModeName(mode);
    BackgroundScore mean;
    for (int k : clip.empty_frames) {
      EXPECT_TRUE(truth.count(k)) << clip.file << " frame " << k;
      if (!truth.count(k) || estimate.size() != truth[k].size()) continue;
      const BackgroundScore s = Score(estimate, truth[k]);
      mean.age += s.age / clip.empty_frames.size();
      mean.peps += s.peps / clip.empty_frames.size();
      mean.psnr_db += s.psnr_db / clip.empty_frames.size();
    }
    std::printf("%-36s %-8s AGE %6.2f  pEPs %6.2f %%  PSNR %6.2f dB\n", clip.file,
                BackgroundModeName(mode).c_str(), mean.age, 100 * mean.peps, mean.psnr_db);
    result[mode] = mean;
  }
  return result;
}

TEST(StaticCamera, CarDetectionRobustModelLearnsTheEmptyParkingLot) {
  FRESCO_REQUIRE_SHARED_DATA();
  const auto r = ScoreClip({"car-detection.mp4", {0, 53, 161, 268}});
  const BackgroundScore& robust = r.at(BackgroundMode::kRobust);
  const BackgroundScore& average = r.at(BackgroundMode::kAverage);
  // The empty frames differ from each other and from the end of the clip (compression
  // noise, wet asphalt): about AGE 5.3 whatever the model (README). No car is left behind:
  // a car left in the estimate costs far more pEPs than 1.2 %, and both models stay at
  // that floor.
  EXPECT_LT(robust.age, 6.0);
  EXPECT_LT(robust.peps, 0.012);
  EXPECT_GT(robust.psnr_db, 28.5);
  EXPECT_LT(robust.age, average.age + 0.3);
}

TEST(StaticCamera, PersonDetectionRobustModelLearnsTheEmptyRoom) {
  FRESCO_REQUIRE_SHARED_DATA();
  const auto r = ScoreClip({"one-by-one-person-detection.mp4", {0}});
  const BackgroundScore& robust = r.at(BackgroundMode::kRobust);
  const BackgroundScore& average = r.at(BackgroundMode::kAverage);
  // Measured: robust AGE 2.23, pEPs 0.28 %, 37.1 dB; average 2.29, 0.44 %, 36.6 dB. A
  // person left in the estimate gives pEPs of several per cent (window 300: 7 %).
  EXPECT_LT(robust.age, 2.6);
  EXPECT_LT(robust.peps, 0.004);
  EXPECT_GT(robust.psnr_db, 36.0);
  EXPECT_LE(robust.peps, average.peps);
}

}  // namespace
}  // namespace fresco
