// Joint adjustment of all poses against the mesh (joint_pose_adjustment.h) on a synthetic
// orbit: the adjusted poses put the scene's points on the image much closer to where the
// true poses put them than the given ones do; at exact poses nothing moves.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/capture.h"
#include "pipeline/core/project.h"
#include "pipeline/eval/eval_suite.h"
#include "pipeline/paint/joint_pose_adjustment.h"
#include "pipeline/render/renderer.h"
#include "pipeline/run/paint_job.h"
#include "pipeline/synth/blocks_scene.h"
#include "pipeline/synth/synth_writer.h"
#include "pipeline/synth/synthesize.h"
#include "tests/paint/synth_session.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

struct Orbit {
  Scene scene;
  SynthCapture capture;
};

SynthOptions OrbitOptions(const BlocksOptions& blocks, double noise_deg, double noise_m) {
  SynthOptions options = testing::BlocksHalfOrbit(blocks, 40, 17);
  options.pose_noise_deg = noise_deg;
  options.pose_noise_m = noise_m;
  return options;
}

Orbit MakeOrbit(double noise_deg, double noise_m) {
  Orbit o;
  BlocksOptions blocks;
  blocks.seed = 5;
  EXPECT_TRUE(MakeBlocksScene(blocks, &o.scene).ok());
  EXPECT_TRUE(
      SynthesizeCapture(o.scene, OrbitOptions(blocks, noise_deg, noise_m), &o.capture).ok());
  return o;
}

std::vector<PoseAdjustFrame> Frames(const Orbit& o) {
  std::vector<PoseAdjustFrame> frames;
  for (size_t i = 0; i < o.capture.frames_bgr.size(); ++i)
    frames.push_back({o.capture.frames_bgr[i], &o.capture.camera,
                      CamFromLocal(o.scene, o.capture.given_poses[i].cam_from_world)});
  return frames;
}

// Mean distance (pixels) between where `cam_from_local` and the true pose put the mesh's
// vertices that the true pose sees in the image, over all frames.
double MeanPixelError(const Orbit& o, const std::vector<Rigid3d>& cam_from_local) {
  const Camera& camera = o.capture.camera;
  double sum = 0;
  long long count = 0;
  for (size_t i = 0; i < cam_from_local.size(); ++i) {
    const Rigid3d truth = CamFromLocal(o.scene, o.capture.true_poses[i].cam_from_world);
    for (const Eigen::Vector3d& v : o.scene.mesh.vertices) {
      Eigen::Vector2d at_truth, at_pose;
      if (!camera.Project(truth * v, &at_truth) || !camera.Project(cam_from_local[i] * v, &at_pose))
        continue;
      if (at_truth.x() < 0 || at_truth.y() < 0 || at_truth.x() > camera.width - 1 ||
          at_truth.y() > camera.height - 1)
        continue;
      sum += (at_pose - at_truth).norm();
      ++count;
    }
  }
  return count > 0 ? sum / count : 0.0;
}

// The orbit's poses adjusted with `options`; `before`, `after`: MeanPixelError at the given
// and at the adjusted poses.
void AdjustOrbit(const Orbit& o, const PoseAdjustOptions& options, PoseAdjustResult* result,
                 double* before, double* after) {
  const std::vector<PoseAdjustFrame> frames = Frames(o);
  std::vector<Rigid3d> given;
  for (const PoseAdjustFrame& f : frames) given.push_back(f.cam_from_local);
  ASSERT_TRUE(AdjustPosesOnMesh(o.scene.mesh, frames, options, result).ok());
  *before = MeanPixelError(o, given);
  *after = MeanPixelError(o, result->cam_from_local);
}

TEST(JointPoseAdjustment, NoisyPosesComeMuchCloserToTheTruth) {
  const Orbit o = MakeOrbit(0.5, 0.01);
  PoseAdjustResult result;
  double before = 0, after = 0;
  ASSERT_NO_FATAL_FAILURE(AdjustOrbit(o, PoseAdjustOptions(), &result, &before, &after));
  std::printf("matches %d (inliers %d), RMS %.3f -> %.3f px; mesh points %.3f -> %.3f px off\n",
              result.matches, result.inliers, result.rms_before_px, result.rms_after_px, before,
              after);
  EXPECT_TRUE(result.applied);
  EXPECT_GT(result.inliers, 500);
  EXPECT_GT(before, 1.5);  // 0.5 degree at f = 229 px is 2 px
  EXPECT_LT(after, 0.1 * before);
  EXPECT_LT(result.rms_after_px, 0.4);
}

// One of the evaluation suites' captures (projects/eval/SUITE.json), synthesized in memory.
struct SuiteCaptureData {
  SynthJob job;
  SynthCapture capture;
  std::vector<PoseAdjustFrame> frames;  // at the given poses
  std::vector<Rigid3d> truth;           // cam_from_local
};

void MakeSuiteCapture(const std::string& suite_name, const std::string& name, SuiteCaptureData* d) {
  EvalSuite suite;
  ASSERT_TRUE(
      LoadEvalSuite(testing::SourceDir() + "/projects/eval/" + suite_name + ".json", &suite).ok());
  ASSERT_TRUE(SelectSuiteCaptures({name}, &suite).ok());
  ASSERT_TRUE(BuildSuiteCaptureJob(suite, suite.captures[0], &d->job).ok());
  ASSERT_TRUE(SynthesizeCapture(d->job.scene, d->job.options, &d->capture).ok());
  for (size_t i = 0; i < d->capture.frames_bgr.size(); ++i) {
    d->frames.push_back({d->capture.frames_bgr[i], &d->capture.camera,
                         CamFromLocal(d->job.scene, d->capture.given_poses[i].cam_from_world)});
    d->truth.push_back(CamFromLocal(d->job.scene, d->capture.true_poses[i].cam_from_world));
  }
}

double Degrees(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return Eigen::AngleAxisd(a * b.inverse()).angle() * 180 / M_PI;
}

// A walk down the evaluation suite's street with 0.4 degree of rotation noise: the camera
// moves forward, so a turn shared by a run of frames hardly shows in their tracks, and small
// errors of the tracks over long gaps (noisier, and a warp of the road interpolated between
// grid points was biased) turned into a drift of 0.15-0.3 degree over the walk's second half.
// Weighted by their spread, through exact warps, the poses come to a quarter of the noise.
TEST(JointPoseAdjustment, AStreetWalkDoesNotDriftWhereTracksAreWeak) {
  SuiteCaptureData d;
  ASSERT_NO_FATAL_FAILURE(MakeSuiteCapture("suite", "street-walk-rot-s23", &d));
  PoseAdjustResult result;
  ASSERT_TRUE(AdjustPosesOnMesh(d.job.scene.mesh, d.frames, PoseAdjustOptions(), &result).ok());
  ASSERT_TRUE(result.applied);
  double given = 0, adjusted = 0, second_half = 0;
  const int n = static_cast<int>(d.frames.size());
  for (int i = 0; i < n; ++i) {
    given += Degrees(d.frames[i].cam_from_local.rotation, d.truth[i].rotation) / n;
    const double error = Degrees(result.cam_from_local[i].rotation, d.truth[i].rotation);
    adjusted += error / n;
    if (i >= n / 2) second_half += error / (n - n / 2);
  }
  std::printf("rotation error: given %.3f deg, adjusted %.3f (second half %.3f)\n", given, adjusted,
              second_half);
  EXPECT_GT(given, 0.3);
  EXPECT_LT(adjusted, 0.25 * given);  // 0.18 before the weighting (0.27 in the second half)
  EXPECT_LT(second_half, 0.4 * given);
}

// A street walk (90 frames) with 5 cm of translation noise, five times the 1 cm prior: with
// priors from the corrections found (the default) the cameras come closer to where they were.
TEST(JointPoseAdjustment, PosesNoisierThanThePriorsAreCorrectedInFull) {
  SuiteCaptureData d;
  ASSERT_NO_FATAL_FAILURE(MakeSuiteCapture("heldout", "street-walk-trans-s1024", &d));
  const int n = static_cast<int>(d.frames.size());
  auto centre_error = [&](const std::vector<Rigid3d>& poses) {
    double sum = 0;
    for (int i = 0; i < n; ++i) sum += (poses[i].Centre() - d.truth[i].Centre()).norm() / n;
    return sum;
  };
  std::vector<Rigid3d> given;
  for (const PoseAdjustFrame& f : d.frames) given.push_back(f.cam_from_local);
  double error[2];
  for (const int rounds : {0, 2}) {
    PoseAdjustOptions options;
    options.prior_rounds = rounds;
    PoseAdjustResult result;
    ASSERT_TRUE(AdjustPosesOnMesh(d.job.scene.mesh, d.frames, options, &result).ok());
    ASSERT_TRUE(result.applied);
    error[rounds > 0] = centre_error(result.cam_from_local);
    std::printf("prior rounds %d: translation prior %.4f m, cameras %.4f m off (given %.4f)\n",
                rounds, result.translation_prior_m, error[rounds > 0], centre_error(given));
    if (rounds > 0) {
      EXPECT_GT(result.translation_prior_m, 0.02);
    }
  }
  EXPECT_LT(error[1], 0.75 * error[0]);  // 20.5 -> 12.2 mm
}

// At exact poses the check decides: the corrections the halves fit to their tracks' own
// errors make the tracks between the halves agree worse, and nothing more is done (no
// adjustment of all the poses: its figures stay 0).
TEST(JointPoseAdjustment, ExactPosesStay) {
  const Orbit o = MakeOrbit(0, 0);
  const std::vector<PoseAdjustFrame> frames = Frames(o);
  PoseAdjustResult result;
  ASSERT_TRUE(AdjustPosesOnMesh(o.scene.mesh, frames, PoseAdjustOptions(), &result).ok());
  std::printf("check: %d tracks, %.3f -> %.3f px (one end), %.3f px (both)\n", result.check_matches,
              result.check_before_px, result.check_one_end_px, result.check_after_px);
  EXPECT_FALSE(result.applied);
  EXPECT_GT(result.check_matches, 200);
  EXPECT_LT(result.check_before_px, 0.5);
  EXPECT_GT(result.check_one_end_px, result.check_before_px / 1.1);
  EXPECT_EQ(result.matches, 0);  // the adjustment itself did not run
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(result.cam_from_local[i].translation, frames[i].cam_from_local.translation);
    EXPECT_EQ(result.cam_from_local[i].rotation.coeffs(),
              frames[i].cam_from_local.rotation.coeffs());
  }
}

// With 0.5 degree and 3 cm of noise the tracks between the halves, which neither half's
// estimate saw, agree several times better at the halves' corrections: the poses are adjusted
// from every track and come close to the truth. Without the check (check_min_improvement 0)
// the same corrections are found.
TEST(JointPoseAdjustment, TheCheckOnFramesLeftOutAppliesNoisyPoses) {
  const Orbit o = MakeOrbit(0.5, 0.03);
  PoseAdjustResult result;
  double before = 0, after = 0;
  ASSERT_NO_FATAL_FAILURE(AdjustOrbit(o, PoseAdjustOptions(), &result, &before, &after));
  std::printf(
      "check: %d tracks, %.3f -> %.3f px (one end), %.3f px (both); mesh points %.3f -> "
      "%.3f px off\n",
      result.check_matches, result.check_before_px, result.check_one_end_px, result.check_after_px,
      before, after);
  EXPECT_TRUE(result.applied);
  EXPECT_GT(result.check_matches, 200);
  // The frame left out keeps its own error, the corrected one loses its: about sqrt(2) better.
  EXPECT_GT(result.check_before_px, 1.25 * result.check_one_end_px);
  EXPECT_GT(result.check_before_px, 3 * result.check_after_px);
  EXPECT_LT(after, 0.15 * before);
  PoseAdjustOptions unchecked;
  unchecked.check_min_improvement = 0;
  PoseAdjustResult always;
  ASSERT_NO_FATAL_FAILURE(AdjustOrbit(o, unchecked, &always, &before, &after));
  EXPECT_TRUE(always.applied);
  EXPECT_EQ(always.check_matches, 0);
  EXPECT_EQ(always.matches, result.matches);
  for (size_t i = 0; i < result.cam_from_local.size(); ++i)
    EXPECT_EQ(always.cam_from_local[i].translation, result.cam_from_local[i].translation);
}

// A long capture is decided on its first frames first: at exact poses nothing more is
// tracked (the given poses stand, the figures are those frames'); with noisy poses the first
// frames pass and the whole capture is adjusted exactly as without the first decision.
TEST(JointPoseAdjustment, ALongCaptureIsDecidedOnItsFirstFrames) {
  PoseAdjustOptions first16;
  first16.decide_on_first_frames = 16;  // the orbit has 40 frames
  PoseAdjustOptions whole;
  whole.decide_on_first_frames = 0;
  const Orbit exact = MakeOrbit(0, 0);
  const std::vector<PoseAdjustFrame> frames = Frames(exact);
  PoseAdjustResult kept;
  ASSERT_TRUE(AdjustPosesOnMesh(exact.scene.mesh, frames, first16, &kept).ok());
  EXPECT_FALSE(kept.applied);
  EXPECT_EQ(kept.decided_on_frames, 16);
  EXPECT_GT(kept.check_matches, 50);
  ASSERT_EQ(kept.cam_from_local.size(), frames.size());
  ASSERT_EQ(kept.frame_matches.size(), frames.size());
  for (size_t i = 0; i < frames.size(); ++i)
    EXPECT_EQ(kept.cam_from_local[i].translation, frames[i].cam_from_local.translation);
  for (size_t i = 16; i < frames.size(); ++i) EXPECT_EQ(kept.frame_matches[i], 0);
  const Orbit noisy = MakeOrbit(0.5, 0.01);
  PoseAdjustResult decided_first, at_once;
  double before = 0, after = 0;
  ASSERT_NO_FATAL_FAILURE(AdjustOrbit(noisy, first16, &decided_first, &before, &after));
  ASSERT_NO_FATAL_FAILURE(AdjustOrbit(noisy, whole, &at_once, &before, &after));
  EXPECT_TRUE(decided_first.applied);
  EXPECT_EQ(decided_first.decided_on_frames, 40);
  EXPECT_EQ(at_once.decided_on_frames, 40);
  EXPECT_EQ(decided_first.matches, at_once.matches);
  for (size_t i = 0; i < at_once.cam_from_local.size(); ++i)
    EXPECT_EQ(decided_first.cam_from_local[i].translation, at_once.cam_from_local[i].translation);
  EXPECT_LT(after, 0.1 * before);
}

// A short capture whose frames are tracked smaller to decide (decide_max_side_px, here 160 px
// for 320x240 frames tracked whole) is decided on all its frames at that size first: at exact
// poses nothing more is tracked; with noisy poses the check there passes and the capture is
// adjusted at full size exactly as without the smaller decision.
TEST(JointPoseAdjustment, AShortCaptureIsDecidedOnSmallerFramesFirst) {
  std::vector<std::string> lines;
  PoseAdjustOptions smaller;
  smaller.max_side_px = 0;
  smaller.decide_max_side_px = 160;
  smaller.progress = [&lines](int, int, const std::string& line) { lines.push_back(line); };
  PoseAdjustOptions whole = smaller;
  whole.decide_max_side_px = 0;
  const Orbit exact = MakeOrbit(0, 0);
  PoseAdjustResult kept;
  ASSERT_TRUE(AdjustPosesOnMesh(exact.scene.mesh, Frames(exact), smaller, &kept).ok());
  EXPECT_FALSE(kept.applied);
  EXPECT_EQ(kept.decided_on_frames, 40);
  EXPECT_EQ(kept.matches, 0);
  ASSERT_FALSE(lines.empty());
  for (const std::string& line : lines)  // every step was the decision's, at the smaller size
    EXPECT_TRUE(line.rfind("deciding: ", 0) == 0 || line.rfind("decided", 0) == 0) << line;
  lines.clear();
  const Orbit noisy = MakeOrbit(0.5, 0.01);
  PoseAdjustResult decided_smaller, at_once;
  double before = 0, after = 0;
  ASSERT_NO_FATAL_FAILURE(AdjustOrbit(noisy, smaller, &decided_smaller, &before, &after));
  EXPECT_TRUE(std::any_of(lines.begin(), lines.end(), [](const std::string& line) {
    return line.rfind("deciding: ", 0) == 0;
  }));
  ASSERT_NO_FATAL_FAILURE(AdjustOrbit(noisy, whole, &at_once, &before, &after));
  EXPECT_TRUE(decided_smaller.applied);
  EXPECT_EQ(decided_smaller.matches, at_once.matches);
  for (size_t i = 0; i < at_once.cam_from_local.size(); ++i)
    EXPECT_EQ(decided_smaller.cam_from_local[i].translation, at_once.cam_from_local[i].translation);
  EXPECT_LT(after, 0.1 * before);
}

TEST(JointPoseAdjustment, FewerThanTwoFramesChangeNothing) {
  const Orbit o = MakeOrbit(0.5, 0.01);
  std::vector<PoseAdjustFrame> frames = Frames(o);
  frames.resize(1);
  PoseAdjustResult result;
  ASSERT_TRUE(AdjustPosesOnMesh(o.scene.mesh, frames, PoseAdjustOptions(), &result).ok());
  EXPECT_FALSE(result.applied);
  ASSERT_EQ(result.cam_from_local.size(), 1u);
  EXPECT_EQ(result.cam_from_local[0].translation, frames[0].cam_from_local.translation);
}

// A capture longer than it holds in memory is left as given, saying why.
TEST(JointPoseAdjustment, ACaptureTooLongToHoldIsNotAdjusted) {
  const Orbit o = MakeOrbit(0.5, 0.01);
  const std::vector<PoseAdjustFrame> frames = Frames(o);
  PoseAdjustOptions options;
  options.max_frames = 30;
  PoseAdjustResult result;
  ASSERT_TRUE(AdjustPosesOnMesh(o.scene.mesh, frames, options, &result).ok());
  EXPECT_FALSE(result.applied);
  EXPECT_EQ(result.not_run, "40 frames, more than the 30 it holds in memory");
  EXPECT_EQ(TooManyFramesToAdjust(30, options), "");
  for (size_t i = 0; i < frames.size(); ++i)
    EXPECT_EQ(result.cam_from_local[i].translation, frames[i].cam_from_local.translation);
}

TEST(JointPoseAdjustment, AFrameOfAnotherSizeIsLeftOut) {
  const Orbit o = MakeOrbit(0.5, 0.01);
  std::vector<PoseAdjustFrame> frames = Frames(o);
  cv::Mat half;
  cv::resize(frames[5].bgr, half, cv::Size(), 0.5, 0.5);
  frames[5].bgr = half;
  PoseAdjustResult result;
  ASSERT_TRUE(AdjustPosesOnMesh(o.scene.mesh, frames, PoseAdjustOptions(), &result).ok());
  EXPECT_TRUE(result.applied);
  EXPECT_EQ(result.frame_matches[5], 0);
  EXPECT_EQ(result.cam_from_local[5].translation, frames[5].cam_from_local.translation);
  EXPECT_GT(result.frame_matches[6], 0);
}

// `fresco run` (and bench, rephoto) read the capture once, adjust its poses and paint with
// them: the job's captures hold the adjusted poses, closer to the truth than the files'.
TEST(JointPoseAdjustment, APaintJobPaintsWithTheAdjustedPoses) {
  const Orbit o = MakeOrbit(0.5, 0.01);
  BlocksOptions blocks;
  blocks.seed = 5;
  const std::string dir = testing::MakeTempDir("joint_pose_job");
  ASSERT_TRUE(
      WriteSynthCapture(o.scene, OrbitOptions(blocks, 0.5, 0.01), dir, SynthWriteOptions()).ok());
  for (const bool joint : {false, true}) {
    Project project;
    ASSERT_TRUE(LoadProject(dir + "/project.json",
                            {std::string("pipeline.refine.joint=") + (joint ? "true" : "false")},
                            &project)
                    .ok());
    std::unique_ptr<PaintJob> job;
    ASSERT_TRUE(OpenPaintJob(project, PaintJobOptions(), &job).ok());
    ASSERT_EQ(job->joint_poses.has_value(), joint);
    std::vector<Rigid3d> poses;
    for (const PosedImage& p : job->captures[0].poses)
      poses.push_back(CamFromLocal(o.scene, p.cam_from_world));  // in the orbit's frame
    ASSERT_EQ(poses.size(), o.capture.true_poses.size());
    const double error = MeanPixelError(o, poses);
    std::printf("joint %d: mesh points %.3f px off\n", joint, error);
    if (joint) {
      EXPECT_TRUE(job->joint_poses->applied);
      EXPECT_LT(error, 0.2);
    } else {
      EXPECT_GT(error, 1.5);
    }
    // The video was opened again: painting reads every frame.
    int frames = 0;
    SourcedFrame frame;
    Status status;
    while (job->source->Next(&frame, &status) == FrameRead::kFrame) ++frames;
    EXPECT_TRUE(status.ok());
    EXPECT_EQ(frames, 40);
  }
  // A frame held out of painting (as `fresco rephoto` and `fresco bench` score them) takes no
  // part and keeps its pose from the file.
  std::vector<Rigid3d> given, held_out;
  for (const int holdout : {-2, 5}) {
    Project project;
    ASSERT_TRUE(
        LoadProject(dir + "/project.json",
                    {std::string("pipeline.refine.joint=") + (holdout >= 0 ? "true" : "false")},
                    &project)
            .ok());
    PaintJobOptions options;
    options.joint_holdout_counter = holdout;
    std::unique_ptr<PaintJob> job;
    ASSERT_TRUE(OpenPaintJob(project, options, &job).ok());
    for (const PosedImage& p : job->captures[0].poses)
      (holdout >= 0 ? held_out : given).push_back(p.cam_from_world);
  }
  ASSERT_EQ(held_out.size(), given.size());
  EXPECT_EQ(held_out[5].translation, given[5].translation);
  EXPECT_EQ(held_out[5].rotation.coeffs(), given[5].rotation.coeffs());
  EXPECT_NE(held_out[6].translation, given[6].translation);
}

// Real data: the TUM teddy's motion-capture poses are painted best as given (applied, the
// adjustment loses 0.8 dB at the photos left out: docs/results.md): fitted to the fused mesh's
// error, the corrections make a frame left out of the estimate agree worse. The check says so
// on the 110k-triangle crop and on the whole 435k-triangle scene alike, well short of its
// threshold (a decision that flips between two meshes of one scene is a defect).
TEST(JointPoseAdjustmentRealData, TheTeddysGivenPosesStandOnItsCropAndOnTheWholeScene) {
  FRESCO_REQUIRE_SHARED_DATA();
  const std::string data = testing::SharedDataDir() + "/tum-rgbd-fr3-teddy/";
  std::vector<double> ratios;
  for (const char* mesh : {"mesh_tsdf_v5mm_teddy_crop.ply", "mesh_tsdf_v10mm.ply"}) {
    Project project;
    ASSERT_TRUE(
        LoadProject(testing::SourceDir() + "/projects/tum-teddy/project.json", {}, &project).ok());
    project.scene = data + mesh;
    Capture capture;
    const Status loaded = LoadCapture(project, CaptureLoadOptions(), &capture);
    ASSERT_TRUE(loaded.ok()) << loaded.message();
    std::vector<PoseAdjustFrame> frames;  // the first 32 posed frames, as a run decides on
    Frame frame;
    Status read;
    while (frames.size() < 32 && capture.video->Next(&frame, &read))
      if (const PosedImage* pose = capture.PoseForFrame(frame))
        frames.push_back({frame.bgr.clone(), capture.CameraFor(*pose),
                          CamFromLocal(capture.scene, pose->cam_from_world)});
    ASSERT_EQ(frames.size(), 32u);
    // Tracked at full size (a run decides these frames at 360 px: not applied either, the
    // ratios 0.81 and 0.72, both ends 1.43 and 1.98 times better).
    PoseAdjustOptions options;
    options.decide_max_side_px = 0;
    PoseAdjustResult result;
    ASSERT_TRUE(AdjustPosesOnMesh(capture.scene.mesh, frames, options, &result).ok());
    std::printf("%s: %d tracks, %.3f -> %.3f px (one end), %.3f px (both)\n", mesh,
                result.check_matches, result.check_before_px, result.check_one_end_px,
                result.check_after_px);
    EXPECT_FALSE(result.applied) << mesh;
    EXPECT_GT(result.check_matches, 1000) << mesh;
    ratios.push_back(result.check_before_px / result.check_one_end_px);
    EXPECT_LT(ratios.back(), 0.95) << mesh;                                  // the threshold is 1.1
    EXPECT_GT(result.check_before_px, 1.8 * result.check_after_px) << mesh;  // fooled, both ends
  }
  EXPECT_NEAR(ratios[0], ratios[1], 0.1);
}

}  // namespace
}  // namespace fresco
