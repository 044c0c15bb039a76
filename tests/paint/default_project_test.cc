// The default project (projects/cube-room: the paper's fig. 8 experiment, 1280x720) painted
// with perfect poses, then the painted model re-rendered and compared with rendering the
// original model: at frame poses and at novel poses between and beside the frames. The
// capture is the project's own (`fresco synth projects/cube-room/synth.json --if-changed`, as
// the README's first command makes it; made here when absent or stale): its frames read back
// from their PNGs (lossless: the pixels rendered), its camera and poses planned from synth.json.
#include <cstdio>
#include <limits>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/image_metrics.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/render/renderer.h"
#include "pipeline/synth/synth_spec.h"
#include "pipeline/synth/synthesize.h"
#include "tests/paint/rephotograph.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

using testing::Rephoto;
using testing::Rephotograph;

TEST(DefaultProject, PerfectPosesRepaintAtLeast35DbAtFrameAndNovelPoses) {
  SynthJob job;
  const std::string spec = testing::SourceDir() + "/projects/cube-room/synth.json";
  ASSERT_TRUE(LoadSynthJob(spec, {}, &job).ok()) << spec;
  SynthCapture plan;
  ASSERT_TRUE(PlanSynthCapture(job.scene, job.options, &plan).ok());
  ASSERT_EQ(plan.camera.width, 1280);
  ASSERT_EQ(plan.camera.height, 720);

  PaintSessionInputs inputs;
  inputs.scene = &job.scene;
  inputs.typical_camera = &plan.camera;
  for (const PosedImage& p : plan.true_poses) inputs.expected_poses.push_back(p.cam_from_world);
  std::unique_ptr<PaintSession> session;
  ASSERT_TRUE(PaintSession::Create(inputs, &session).ok());
  const testing::CommandResult made = testing::RunFresco({"synth", spec, "--if-changed"});
  ASSERT_EQ(made.exit_code, 0) << made.err;
  const std::string frames = testing::SourceDir() + "/projects/cube-room/capture/frames/";
  FrameReport report;
  for (size_t index = 0; index < plan.true_poses.size(); ++index) {
    char name[16];
    std::snprintf(name, sizeof(name), "%06zu.png", index);
    Frame frame;
    frame.index = static_cast<int>(index);
    frame.bgr = cv::imread(frames + name, cv::IMREAD_COLOR);
    ASSERT_EQ(frame.bgr.size(), cv::Size(plan.camera.width, plan.camera.height)) << frames << name;
    session->PaintFrame(frame, plan.camera, plan.true_poses[index].cam_from_world, &report);
  }
  const Scene painted = session->PaintedScene();

  const Renderer renderer = testing::RephotoRenderer(plan.camera);
  const int n = static_cast<int>(plan.true_poses.size());
  double worst_frame = std::numeric_limits<double>::infinity(), worst_novel = worst_frame;
  double sum = 0;
  int count = 0;
  for (int i = 0; i < n; i += 15) {
    const Rigid3d& a = plan.true_poses[i].cam_from_world;
    const Rephoto at_frame = Rephotograph(renderer, job.scene, painted, a);
    // Novel: half-way to the next frame, and 10 cm beside the frame's camera.
    const Rigid3d& b = plan.true_poses[std::min(i + 1, n - 1)].cam_from_world;
    const Rigid3d between(a.rotation.slerp(0.5, b.rotation), 0.5 * (a.translation + b.translation));
    Rigid3d beside = a;
    beside.translation -= Eigen::Vector3d(0.1, 0.05, 0.0);  // camera moves +x, +y in its frame
    const Rephoto at_between = Rephotograph(renderer, job.scene, painted, between);
    const Rephoto at_beside = Rephotograph(renderer, job.scene, painted, beside);
    std::printf(
        "frame %3d: %.2f dB (%.1f %% complete); between %.2f dB; beside %.2f dB (%.1f %%)\n", i,
        at_frame.psnr_db, 100 * at_frame.completeness, at_between.psnr_db, at_beside.psnr_db,
        100 * at_beside.completeness);
    EXPECT_GE(at_frame.completeness, 0.95) << "frame " << i;
    EXPECT_GE(at_between.completeness, 0.95) << "between frame " << i << " and the next";
    worst_frame = std::min(worst_frame, at_frame.psnr_db);
    worst_novel = std::min({worst_novel, at_between.psnr_db, at_beside.psnr_db});
    sum += at_frame.psnr_db + at_between.psnr_db + at_beside.psnr_db;
    count += 3;
  }
  std::printf(
      "default project: worst %.2f dB at frame poses, %.2f dB at novel poses, mean %.2f dB; "
      "coverage %.1f %%\n",
      worst_frame, worst_novel, sum / count, 100 * session->Coverage());
  EXPECT_GE(worst_frame, 35.0);
  EXPECT_GE(worst_novel, 35.0);
}

}  // namespace
}  // namespace fresco
