// The painting job (pipeline/run) on its own: the frame policy on each kind of bad frame,
// the run's counts (frames read, painted, without a pose, held out; per stream) on small
// synthetic captures, max_frames, and several streams interleaved.
#include <cmath>
#include <filesystem>
#include <thread>

#include <gtest/gtest.h>

#include "pipeline/core/project.h"
#include "pipeline/run/frame_policy.h"
#include "pipeline/run/paint_job.h"
#include "pipeline/run/paint_run.h"
#include "tests/live/stream_support.h"
#include "tests/run/bad_captures.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using testing::BadCapture;
using testing::MakeBadCapture;

Camera Camera160x120() {
  Camera camera;
  camera.width = 160, camera.height = 120;
  return camera;
}

SourcedFrame FrameOfSize(int width, int height, bool posed, const Camera* camera) {
  SourcedFrame f;
  f.posed.frame.name = "000004.png";
  f.posed.frame.bgr = cv::Mat(height, width, CV_8UC3, cv::Scalar(0, 0, 0));
  f.posed.has_pose = posed;
  f.camera = camera;
  f.camera_id = 7;
  f.pose_name = "000004.png";
  return f;
}

const FrameOrigin kOrigin{"/c/frames", "/c/sparse/images.txt"};

TEST(FramePolicy, PosedFrameOfTheCamerasSizeIsPainted) {
  const Camera camera = Camera160x120();
  FrameFate fate = FrameFate::kNoPose;
  ASSERT_TRUE(ApplyFramePolicy(FrameOfSize(160, 120, true, &camera), kOrigin, &fate).ok());
  EXPECT_EQ(fate, FrameFate::kPaint);
}

TEST(FramePolicy, FrameWithoutAPoseIsSkippedNotAnError) {
  FrameFate fate = FrameFate::kPaint;
  ASSERT_TRUE(ApplyFramePolicy(FrameOfSize(80, 60, false, nullptr), kOrigin, &fate).ok());
  EXPECT_EQ(fate, FrameFate::kNoPose);
}

TEST(FramePolicy, UnknownCameraNamesThePosesFileAndImage) {
  FrameFate fate;
  const Status s = ApplyFramePolicy(FrameOfSize(160, 120, true, nullptr), kOrigin, &fate);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message(), "/c/sparse/images.txt: image '000004.png': camera 7 not found");
}

TEST(FramePolicy, FrameOfAnotherSizeNamesTheVideoAndFrame) {
  const Camera camera = Camera160x120();
  FrameFate fate;
  const Status s = ApplyFramePolicy(FrameOfSize(80, 60, true, &camera), kOrigin, &fate);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message(), "/c/frames: frame '000004.png' is 80x60 but the camera is 160x120");
}

// A source of prepared frames (no files): the run applies the policy to whatever it gets.
class ListSource : public PosedFrameSource {
 public:
  explicit ListSource(std::vector<SourcedFrame> frames) : frames_(std::move(frames)) {}
  FrameRead Next(SourcedFrame* frame, Status*) override {
    if (next_ >= frames_.size()) return FrameRead::kEnded;
    *frame = frames_[next_++];
    return FrameRead::kFrame;
  }
  int NumStreams() const override { return 1; }
  const FrameOrigin& Origin(int) const override { return kOrigin; }
  void Stop() override { ++stops; }
  int stops = 0;

 private:
  std::vector<SourcedFrame> frames_;
  size_t next_ = 0;
};

TEST(PaintRun, UnknownCameraFromAnySourceEndsTheRunWithThePolicysError) {
  ListSource source({FrameOfSize(80, 60, false, nullptr), FrameOfSize(160, 120, true, nullptr),
                     FrameOfSize(160, 120, false, nullptr)});
  PaintRun run(nullptr, &source, PaintRunOptions());  // nothing reaches painting
  const Status s = RunToEnd(&run, PaintRunHooks());
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message(), "/c/sparse/images.txt: image '000004.png': camera 7 not found");
  EXPECT_EQ(run.stats().frames, 2);
  EXPECT_EQ(run.stats().frames_without_pose, 1);
  EXPECT_TRUE(run.ended());
  EXPECT_GE(source.stops, 1);
}

// Opens `project_json` as `fresco run` does and runs it to the end with `options`.
struct Ran {
  Status status;
  PaintRunStats stats;
  std::vector<std::string> held_out;  // names of the held-out frames
  std::vector<int> stream_order;      // stream of each frame read
  std::string end_reason;             // PaintRun::EndReason()
};
Ran RunJob(const std::string& project_json, const PaintRunOptions& options,
           const std::vector<std::string>& overrides = {},
           const PaintJobOptions& job_options = PaintJobOptions()) {
  Project project;
  Ran ran;
  ran.status = LoadProject(project_json, overrides, &project);
  if (!ran.status.ok()) return ran;
  std::unique_ptr<PaintJob> job;
  ran.status = OpenPaintJob(project, job_options, &job);
  if (!ran.status.ok()) return ran;
  PaintRun run(job->session.get(), job->source.get(), options);
  PaintRunHooks hooks;
  hooks.after_frame = [&](const RunFrame& f, const FrameReport*) {
    if (f.fate == FrameFate::kHeldOut) ran.held_out.push_back(f.posed.frame.name);
    ran.stream_order.push_back(f.stream);
    return Status::Ok();
  };
  ran.status = RunToEnd(&run, hooks);
  ran.stats = run.stats();
  ran.end_reason = run.EndReason();
  return ran;
}

TEST(PaintRun, FrameWithoutAPoseIsCountedAndTheRestPainted) {
  const Ran r = RunJob(MakeBadCapture(BadCapture::kMissingPose), PaintRunOptions());
  ASSERT_TRUE(r.status.ok()) << r.status.message();
  EXPECT_EQ(r.stats.frames, 12);
  EXPECT_EQ(r.stats.frames_without_pose, 1);
  EXPECT_EQ(r.stats.frames_painted, 11);
  EXPECT_EQ(r.stats.frames_held_out, 0);
  EXPECT_EQ(r.end_reason, "end of video");
  ASSERT_EQ(r.stats.streams.size(), 1u);
  EXPECT_EQ(r.stats.streams[0].frames, 12);
  EXPECT_EQ(r.stats.streams[0].painted, 11);
  EXPECT_EQ(r.stats.streams[0].without_pose, 1);
  // Every stage reported on every painted frame.
  ASSERT_TRUE(r.stats.MeanStageMs().count("warp"));
  EXPECT_GT(r.stats.MeanStageMs().at("warp"), 0.0);
  EXPECT_GT(r.stats.Fps(), 0.0);
}

TEST(PaintRun, HoldoutTakesEveryNthPosedFrameOutOfPainting) {
  PaintRunOptions options;
  options.holdout_every = 4;  // counters 2, 6, 10
  const Ran r = RunJob(MakeBadCapture(BadCapture::kMissingPose), options);
  ASSERT_TRUE(r.status.ok()) << r.status.message();
  EXPECT_EQ(r.held_out, (std::vector<std::string>{"000002.png", "000006.png", "000010.png"}));
  EXPECT_EQ(r.stats.frames_held_out, 3);
  EXPECT_EQ(r.stats.frames_without_pose, 1);
  EXPECT_EQ(r.stats.frames_painted, 8);
}

TEST(PaintRun, MaxFramesEndsTheRunWithoutAnError) {
  PaintRunOptions options;
  options.max_frames = 4;
  const Ran r = RunJob(testing::GoodCaptureDir() + "/project.json", options);
  ASSERT_TRUE(r.status.ok()) << r.status.message();
  EXPECT_EQ(r.stats.frames, 4);
  EXPECT_EQ(r.stats.frames_painted, 4);
  EXPECT_EQ(r.end_reason, "pipeline.max_frames (4) reached");
}

// A folder's frame without a pose is not decoded (nothing paints it): a broken file there
// passes, counted as a frame without a pose, before painting and while painting. The app,
// which shows every frame, reads it and stops at it.
TEST(PaintRun, AFrameWithoutAPoseIsNotDecoded) {
  const std::string project = MakeBadCapture(BadCapture::kMissingPose);
  const std::string file = fs::path(project).parent_path().string() + "/frames/000003.png";
  testing::WriteText(file, "this is not a PNG");
  const Ran r = RunJob(project, PaintRunOptions());
  ASSERT_TRUE(r.status.ok()) << r.status.message();
  EXPECT_EQ(r.stats.frames, 12);
  EXPECT_EQ(r.stats.frames_without_pose, 1);
  EXPECT_EQ(r.stats.frames_painted, 11);
  PaintJobOptions as_the_app;
  as_the_app.read_frames_without_pose = true;
  const Ran shown = RunJob(project, PaintRunOptions(), {}, as_the_app);
  ASSERT_FALSE(shown.status.ok());
  EXPECT_EQ(shown.status.message().rfind(file + ": ", 0), 0u) << shown.status.message();
}

// A frame the whole-capture pre-pass decoded is painted from what it decoded, not read again:
// broken on disk after the job opened, it still paints.
TEST(PaintRun, AFrameDecodedBeforePaintingIsNotDecodedAgain) {
  const std::string project_json = MakeBadCapture(BadCapture::kMissingPose);
  Project project;
  ASSERT_TRUE(LoadProject(project_json, {}, &project).ok());
  ASSERT_TRUE(project.pipeline.refine.joint);  // the defaults read the capture before painting
  std::unique_ptr<PaintJob> job;
  ASSERT_TRUE(OpenPaintJob(project, PaintJobOptions(), &job).ok());
  testing::WriteText(fs::path(project_json).parent_path().string() + "/frames/000005.png",
                     "this is not a PNG");
  PaintRun run(job->session.get(), job->source.get(), PaintRunOptions());
  const Status status = RunToEnd(&run, PaintRunHooks());
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(run.stats().frames_painted, 11);  // all but the frame without a pose
}

// Painting frame by frame, the run ends at the broken frame; with the joint pose adjustment
// or the background's `auto` and `across_views` (the defaults for captures from files) the
// capture is read before painting, and the same error comes before any frame is painted.
TEST(PaintRun, CorruptImageEndsTheRunNamingTheFile) {
  const std::string project = MakeBadCapture(BadCapture::kCorruptImage);
  const std::string file = fs::path(project).parent_path().string() + "/frames/000005.png";
  const Ran frame_by_frame =
      RunJob(project, PaintRunOptions(),
             {"pipeline.refine.joint=false", "pipeline.background.mode=robust",
              "pipeline.background.across_views=false"});
  ASSERT_FALSE(frame_by_frame.status.ok());
  EXPECT_EQ(frame_by_frame.status.message().rfind(file + ": ", 0), 0u)
      << frame_by_frame.status.message();
  EXPECT_EQ(frame_by_frame.stats.frames, 5);  // 000000 .. 000004, then the error
  EXPECT_EQ(frame_by_frame.stats.frames_painted, 5);
  const Ran adjusted = RunJob(project, PaintRunOptions());
  ASSERT_FALSE(adjusted.status.ok());
  EXPECT_EQ(adjusted.status.message(), frame_by_frame.status.message());
  EXPECT_EQ(adjusted.stats.frames_painted, 0);
}

TEST(PaintRun, FramesSmallerThanTheCameraEndTheRunAtTheFirst) {
  const std::string project = MakeBadCapture(BadCapture::kFramesSmallerThanCamera);
  const Ran r = RunJob(project, PaintRunOptions());
  ASSERT_FALSE(r.status.ok());
  const std::string frames = fs::path(project).parent_path().string() + "/frames/";
  EXPECT_EQ(r.status.message(), frames + ": frame '000000.png' is 80x60 but the camera is 160x120");
  EXPECT_EQ(r.stats.frames, 1);
  EXPECT_EQ(r.stats.frames_painted, 0);
}

// Live, with the time offset estimated on the first frames before any is painted: the
// estimate paints none of them (they are not the camera's size), and the run ends at the
// first with the frame policy's message.
TEST(PaintRun, LiveFramesSmallerThanTheCameraEndTheRunAtTheFirstWhileTheOffsetIsEstimated) {
  testing::PoseServer server;
  const testing::LiveBadCapture capture = testing::MakeLiveSmallFramesCapture(server.port());
  std::thread tracker([&] { testing::ServeTrack(&server, capture.truth, 30.0, 0.0); });
  const Ran r = RunJob(capture.project, PaintRunOptions());
  tracker.join();
  ASSERT_FALSE(r.status.ok());
  EXPECT_EQ(r.status.message(), capture.first_frame_error);
  EXPECT_EQ(r.stats.frames_painted, 0);
}

TEST(PaintRun, UnknownCameraIdIsRefusedWhenTheJobOpens) {
  const Ran r = RunJob(MakeBadCapture(BadCapture::kUnknownCameraId), PaintRunOptions());
  ASSERT_FALSE(r.status.ok());
  EXPECT_NE(r.status.message().find("image '000003.png'"), std::string::npos) << r.status.message();
  EXPECT_NE(r.status.message().find("CAMERA_ID 7"), std::string::npos) << r.status.message();
  EXPECT_EQ(r.stats.frames, 0);
}

// The figures other code reads back are typed (FrameReport::paint): the string-keyed view of
// panels and metrics.json is made from them, so both say the same.
TEST(PaintRun, TypedPaintFiguresAreWhatTheMetricsShow) {
  Project project;
  ASSERT_TRUE(LoadProject(testing::GoodCaptureDir() + "/project.json", {}, &project).ok());
  std::unique_ptr<PaintJob> job;
  ASSERT_TRUE(OpenPaintJob(project, PaintJobOptions(), &job).ok());
  PaintRun run(job->session.get(), job->source.get(), PaintRunOptions());
  int compared = 0, painted = 0;
  PaintRunHooks hooks;
  hooks.after_frame = [&](const RunFrame&, const FrameReport* report) {
    if (!report) return Status::Ok();
    ++painted;
    const double typed = report->paint.difference_to_buffer;
    const double shown = report->Stage("paint")->metrics.at("difference_to_buffer");
    if (std::isnan(typed)) {
      EXPECT_TRUE(std::isnan(shown));
    } else {
      EXPECT_EQ(typed, shown);
      EXPECT_GE(typed, 0.0);
      EXPECT_LT(typed, 64.0);  // the synthetic frames agree with what is painted
      ++compared;
    }
    return Status::Ok();
  };
  ASSERT_TRUE(RunToEnd(&run, hooks).ok());
  EXPECT_EQ(painted, 12);
  EXPECT_GE(compared, 10);  // every frame after the first sees painted texels
}

// Two streams (the good poses, and the same frames with frame 3's pose missing): frames
// interleave stream by stream and each stream keeps its own counts.
TEST(PaintRun, TwoStreamsInterleaveAndCountPerStream) {
  const Ran r = RunJob(testing::MakeTwoStreamCapture(), PaintRunOptions());
  ASSERT_TRUE(r.status.ok()) << r.status.message();
  EXPECT_EQ(r.stats.frames, 24);
  ASSERT_EQ(r.stats.streams.size(), 2u);
  EXPECT_EQ(r.stats.streams[0].frames, 12);
  EXPECT_EQ(r.stats.streams[0].painted, 12);
  EXPECT_EQ(r.stats.streams[0].without_pose, 0);
  EXPECT_EQ(r.stats.streams[1].frames, 12);
  EXPECT_EQ(r.stats.streams[1].painted, 11);
  EXPECT_EQ(r.stats.streams[1].without_pose, 1);
  ASSERT_EQ(r.stream_order.size(), 24u);
  for (size_t i = 0; i < r.stream_order.size(); ++i) EXPECT_EQ(r.stream_order[i], int(i % 2));
}

}  // namespace
}  // namespace fresco

namespace fresco {
namespace {

// `update: auto` through the one frame loop: on a capture whose frames change exposure,
// 6 frames held out of the decision, spread over the capture (of 40 frames every 5th: 2, 7,
// ..., 27), agree better with the mean of every view painted without them (decided after
// frame 29); every frame is read, painted and counted once, in order; and what the run paints
// is what `update: mean` paints.
TEST(PaintRun, UpdateAutoDecidesOnFramesHeldOutOfTheDecisionAndPaintsEveryFrameInOrder) {
  const std::string dir = testing::MakeTempDir("update-auto") + "/capture";
  const testing::CommandResult synth = testing::RunFresco(
      {"synth", "--scene", "builtin:cube-room", "--out", dir, "--frames", "40", "--size",
       "160x120", "--exposure", "0.1", "--seed", "7", "--supersample", "1"});
  ASSERT_EQ(synth.exit_code, 0) << synth.err;
  Project project;
  ASSERT_TRUE(LoadProject(dir + "/project.json", {"pipeline.update=auto"}, &project).ok());
  std::unique_ptr<PaintJob> job;
  ASSERT_TRUE(OpenPaintJob(project, PaintJobOptions(), &job).ok());
  PaintRun run(job->session.get(), job->source.get(), PaintRunOptions());
  std::vector<int> order;
  PaintRunHooks hooks;
  hooks.after_frame = [&](const RunFrame& frame, const FrameReport* report) {
    if (report) order.push_back(frame.counter);
    return Status::Ok();
  };
  ASSERT_TRUE(RunToEnd(&run, hooks).ok());
  EXPECT_EQ(run.stats().frames, 40);
  EXPECT_EQ(run.stats().frames_painted, 40);
  std::vector<int> in_order(40);
  for (int k = 0; k < 40; ++k) in_order[k] = k;
  EXPECT_EQ(order, in_order);
  const AutoDecision decided = job->session->auto_decisions().update;
  EXPECT_EQ(decided.state, AutoDecision::State::kOn);  // the mean
  EXPECT_EQ(decided.frames_measured, 6);
  EXPECT_EQ(decided.decided_at_frame, 30);
  EXPECT_GT(decided.evidence, 0.3);
  EXPECT_EQ(job->session->options().update, UpdatePolicy::kMean);

  Project mean = project;
  mean.pipeline.update = UpdatePolicy::kMean;
  std::unique_ptr<PaintJob> mean_job;
  ASSERT_TRUE(OpenPaintJob(mean, PaintJobOptions(), &mean_job).ok());
  PaintRun mean_run(mean_job->session.get(), mean_job->source.get(), PaintRunOptions());
  ASSERT_TRUE(RunToEnd(&mean_run, PaintRunHooks()).ok());
  EXPECT_DOUBLE_EQ(mean_job->session->Coverage(), job->session->Coverage());
  for (size_t b = 0; b < job->session->painted().size(); ++b)
    EXPECT_LE(cv::norm(job->session->painted()[b].bgra, mean_job->session->painted()[b].bgra,
                       cv::NORM_INF),
              1.0)
        << "buffer " << b;  // float sums, one conversion more: at most 1 grey level apart
}

}  // namespace
}  // namespace fresco
