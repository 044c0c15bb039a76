// Every client opens and paints a project through one door (pipeline/run: OpenPaintJob with
// its whole-capture pre-pass, PaintRun with its frame policy): the app's painting worker
// paints the same project with the same settings to the same texture as `fresco run`, bit
// for bit; and PaintFrame itself refuses a frame that is not its camera's size.
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "pipeline/core/project.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/run/paint_job.h"
#include "pipeline/run/paint_run.h"
#include "tests/live/stream_support.h"
#include "tests/run/bad_captures.h"
#include "tests/run/play_in_app.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

using testing::CommandResult;
using testing::MakeTempDir;
using testing::ReadText;
using testing::RunFresco;

Project Load(const std::string& path) {
  Project project;
  const Status loaded = LoadProject(path, {}, &project);
  EXPECT_TRUE(loaded.ok()) << loaded.message();
  return project;
}

// A short street walk with two movers, noisy poses and exposure changes: with the defaults
// the whole-capture pre-pass runs (movers across views decide the background) and the auto
// modes decide; what the app painted without the pre-pass differed.
std::string StreetProject() {
  static const std::string project = [] {
    const std::string dir = MakeTempDir("one-door-street") + "/capture";
    const CommandResult r = RunFresco(
        {"synth", "--scene", "builtin:street", "--out", dir, "--frames", "30", "--size",
         "320x240", "--lens", "opencv5", "--movers", "2", "--pose-noise-deg", "0.3",
         "--pose-noise-m", "0.03", "--exposure", "0.05", "--supersample", "1", "--seed", "4"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return dir + "/project.json";
  }();
  return project;
}

TEST(OneDoor, TheAppPaintsTheStreetToTheSameTextureAsFrescoRun) {
  const std::string project_json = StreetProject();
  const Project project = Load(project_json);

  // `fresco run`, as a user runs it.
  const std::string out = MakeTempDir("one-door-run") + "/out";
  const CommandResult run = RunFresco({"run", project_json, "--out", out, "--quiet"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json metrics = nlohmann::json::parse(ReadText(out + "/metrics.json"));

  // What `fresco run` paints, in process (its buffers before the atlas): the job layer.
  std::unique_ptr<PaintJob> job;
  ASSERT_TRUE(OpenPaintJob(project, PaintJobOptions(), &job).ok());
  ASSERT_TRUE(job->mover_masks.has_value()) << "the pre-pass did not run: the test tests nothing";
  PaintRunOptions run_options;
  PaintRun paint_run(job->session.get(), job->source.get(), run_options);
  ASSERT_TRUE(RunToEnd(&paint_run, PaintRunHooks()).ok());
  EXPECT_DOUBLE_EQ(job->session->Coverage(), metrics["coverage"].get<double>());

  const auto app = testing::PlayInApp(project_json);
  EXPECT_EQ(app->status, "end of video");
  EXPECT_DOUBLE_EQ(app->coverage, metrics["coverage"].get<double>());
  const std::vector<PaintedBuffer>& painted = job->session->painted();
  ASSERT_TRUE(app->painted);
  ASSERT_EQ(app->painted->size(), painted.size());
  for (size_t b = 0; b < painted.size(); ++b) {
    const cv::Mat& in_app = (*app->painted)[b];
    ASSERT_EQ(in_app.size(), painted[b].bgra.size()) << "buffer " << b;
    EXPECT_EQ(cv::norm(in_app, painted[b].bgra, cv::NORM_INF), 0.0) << "buffer " << b;
  }
}

// A live project with two cameras replayed: each stream's frames from a folder, its poses from
// a tracker over TCP (matched by time). With the defaults, the job `fresco run` opens, the
// app's worker and `fresco run` itself paint it the same: the same buffers bit for bit (no
// stream is real time, so the streams take strict turns), the same coverage.
TEST(OneDoor, TheAppPaintsALiveTwoStreamReplayAsFrescoRunDoes) {
  const std::string dir = MakeTempDir("one-door-live-two");
  const int frames = 16;
  const testing::TwoStreamCaptures c = testing::MakeTwoStreamCaptures(dir, frames);
  testing::PoseServer servers[2];
  nlohmann::json streams = nlohmann::json::array();
  for (int s = 0; s < 2; ++s)
    streams.push_back({{"camera", c.dir[s] + "/camera.cameramodel"},
                       {"video", c.dir[s] + "/frames/"},
                       {"poses", servers[s].Address()}});
  const nlohmann::json project_file = {
      {"fresco", 2},
      {"scene", dir + "/a/scene.gltf"},
      {"streams", streams},
      {"pipeline", {{"texel_size_m", 0.03}}},
      {"live", {{"connect_timeout_s", 10}, {"read_timeout_s", 2}}}};
  const std::string project_json = dir + "/live.json";
  testing::WriteText(project_json, project_file.dump(2));
  // Serves both tracks once (to one client) while `paint` runs.
  const auto with_trackers = [&](const auto& paint) {
    std::thread trackers[2];
    for (int s = 0; s < 2; ++s)
      trackers[s] = std::thread(testing::ServeTrack, &servers[s], c.truth[s], 30.0, 0.0);
    paint();
    for (std::thread& tracker : trackers) tracker.join();
  };

  // The job `fresco run` opens, in process; closed before the next client connects (its pose
  // feeds would reconnect to the trackers).
  std::vector<cv::Mat> painted;
  double coverage = 0;
  with_trackers([&] {
    std::unique_ptr<PaintJob> job;
    ASSERT_TRUE(OpenPaintJob(Load(project_json), PaintJobOptions(), &job).ok());
    PaintRun paint_run(job->session.get(), job->source.get(), PaintRunOptions());
    ASSERT_TRUE(RunToEnd(&paint_run, PaintRunHooks()).ok());
    EXPECT_EQ(paint_run.stats().frames_painted, 2 * frames);
    for (const PaintedBuffer& buffer : job->session->painted()) painted.push_back(buffer.bgra);
    coverage = job->session->Coverage();
  });

  std::shared_ptr<const RunnerSnapshot> app;
  with_trackers([&] { app = testing::PlayInApp(project_json); });
  EXPECT_EQ(app->run.frames_painted, 2 * frames)
      << app->status << "; read " << app->run.frames << ", without pose "
      << app->run.frames_without_pose;
  ASSERT_TRUE(app->painted);
  ASSERT_EQ(app->painted->size(), painted.size());
  for (size_t b = 0; b < painted.size(); ++b) {
    const cv::Mat& in_app = (*app->painted)[b];
    ASSERT_EQ(in_app.size(), painted[b].size()) << "buffer " << b;
    EXPECT_EQ(cv::norm(in_app, painted[b], cv::NORM_INF), 0.0) << "buffer " << b;
  }
  EXPECT_DOUBLE_EQ(app->coverage, coverage);

  const std::string out = dir + "/out";
  CommandResult run;
  with_trackers([&] { run = RunFresco({"run", project_json, "--out", out, "--quiet"}); });
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json metrics = nlohmann::json::parse(ReadText(out + "/metrics.json"));
  EXPECT_EQ(metrics["frames_painted"], 2 * frames);
  EXPECT_DOUBLE_EQ(metrics["coverage"].get<double>(), coverage);
}

// PaintFrame checks its own precondition: a frame not of its camera's size is an internal
// error (exit 1 from a verb), never a read out of bounds.
TEST(OneDoor, PaintFrameRefusesAFrameNotOfItsCamerasSize) {
  const Project project = Load(testing::GoodCaptureDir() + "/project.json");
  std::unique_ptr<PaintJob> job;
  ASSERT_TRUE(OpenPaintJob(project, PaintJobOptions(), &job).ok());
  const Camera& camera = job->captures[0].cameras.begin()->second;
  Frame frame;
  frame.name = "small.png";
  frame.bgr = cv::Mat(camera.height / 2, camera.width / 2, CV_8UC3, cv::Scalar(9, 9, 9));
  FrameReport report;
  const Rigid3d pose = job->captures[0].poses[0].cam_from_world;
  EXPECT_THROW(job->session->PaintFrame(frame, camera, pose, &report), std::logic_error);
  frame.bgr = cv::Mat(camera.height, camera.width, CV_8UC1, cv::Scalar(9));
  EXPECT_THROW(job->session->PaintFrame(frame, camera, pose, &report), std::logic_error);
  EXPECT_EQ(job->session->NumPaintedSurfaceTexels(), 0);
}

}  // namespace
}  // namespace fresco
