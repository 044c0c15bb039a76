// Every client opens and paints a project through one door (pipeline/run: OpenPaintJob with
// its whole-capture pre-pass, PaintRun with its frame policy): the app's painting worker
// paints the same project with the same settings to the same texture as `fresco run`, bit
// for bit; and PaintFrame itself refuses a frame that is not its camera's size.
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "pipeline/core/project.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/run/paint_job.h"
#include "pipeline/run/paint_run.h"
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
