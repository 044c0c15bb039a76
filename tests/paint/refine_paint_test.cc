// Refinement in the pipeline, against ground truth: a synthetic capture whose given poses
// carry noise is painted with refinement off, in the paper's mode and in the robust mode;
// the painted model is re-rendered at the true poses and compared with the original model.
// Measured (printed): the registration residual drops, but the PSNR at the true poses is not
// recovered: each buffer is first painted by a frame with its own pose error, and later
// frames registered to the buffer inherit that offset. The test holds what is achieved:
// residual at least halved, and no PSNR lost by refining.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/image_metrics.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/render/renderer.h"
#include "pipeline/synth/procedural_scenes.h"
#include "pipeline/synth/synthesize.h"
#include "tests/paint/rephotograph.h"

namespace fresco {
namespace {

struct Painted {
  std::unique_ptr<PaintSession> session;
  Scene scene;
  double refine_before_px = 0, refine_after_px = 0;
  int refined = 0;
};

Painted Paint(const Scene& scene, const SynthCapture& capture, const std::vector<PosedImage>& poses,
              const PipelineOptions& options) {
  Painted p;
  PaintSessionInputs inputs;
  inputs.scene = &scene;
  inputs.pipeline = options;
  inputs.typical_camera = &capture.camera;
  for (const auto& pose : capture.true_poses) inputs.expected_poses.push_back(pose.cam_from_world);
  EXPECT_TRUE(PaintSession::Create(inputs, &p.session).ok());
  FrameReport report;
  int n = 0;
  for (size_t i = 0; i < capture.frames_bgr.size(); ++i) {
    Frame frame;
    frame.index = static_cast<int>(i);
    frame.bgr = capture.frames_bgr[i];
    p.session->PaintFrame(frame, capture.camera, poses[i].cam_from_world, &report);
    if (const StageReport* r = report.Stage("refine"); r && r->metrics.at("inliers") > 0) {
      p.refine_before_px += r->metrics.at("residual_before_px");
      p.refine_after_px += r->metrics.at("residual_after_px");
      p.refined += static_cast<int>(r->metrics.at("buffers_refined"));
      ++n;
    }
  }
  if (n > 0) p.refine_before_px /= n, p.refine_after_px /= n;
  p.scene = p.session->PaintedScene();
  return p;
}

// Mean PSNR of the painted model against the original at the true poses (every 6th frame).
double MeanPsnr(const Scene& original, const Scene& painted, const SynthCapture& capture) {
  const Renderer renderer = testing::RephotoRenderer(capture.camera);
  double sum = 0;
  int n = 0;
  for (size_t i = 0; i < capture.true_poses.size(); i += 6, ++n)
    sum += testing::Rephotograph(renderer, original, painted, capture.true_poses[i].cam_from_world)
               .psnr_db;
  return sum / n;
}

TEST(RefinePainting, RegistersNoisyFramesToTheBuffersWithoutLosingPsnr) {
  CubeRoomOptions room;
  room.procedural_texture_px = 1024;
  Scene scene;
  ASSERT_TRUE(MakeCubeRoomScene(room, &scene).ok());
  SynthOptions o;
  o.frames = 60;
  o.width = 320;
  o.height = 240;
  o.hfov_deg = 70;
  o.path = CameraPathKind::kHandheld;
  o.target = Eigen::Vector3d(0, 1.5, 0);
  o.radius_m = 0.6;
  o.height_m = 1.5;
  o.turns = 0.5;
  o.pose_noise_deg = 0.5;
  o.seed = 11;
  SynthCapture capture;
  ASSERT_TRUE(SynthesizeCapture(scene, o, &capture).ok());
  PipelineOptions options;
  options.background.mode = BackgroundMode::kOff;  // measure refinement alone
  const double perfect =
      MeanPsnr(scene, Paint(scene, capture, capture.true_poses, options).scene, capture);
  const double noisy =
      MeanPsnr(scene, Paint(scene, capture, capture.given_poses, options).scene, capture);
  options.refine.mode = RefineMode::kPaper;
  const Painted paper = Paint(scene, capture, capture.given_poses, options);
  const double paper_psnr = MeanPsnr(scene, paper.scene, capture);
  options.refine.mode = RefineMode::kRobust;
  const Painted robust = Paint(scene, capture, capture.given_poses, options);
  const double robust_psnr = MeanPsnr(scene, robust.scene, capture);
  const double recovered = (robust_psnr - noisy) / (perfect - noisy);
  std::printf(
      "PSNR at true poses: perfect %.2f dB, 0.5 deg noise %.2f dB, paper refinement %.2f dB, "
      "robust %.2f dB (recovers %.0f %%); robust residual %.2f -> %.2f texels, %d buffers "
      "refined\n",
      perfect, noisy, paper_psnr, robust_psnr, 100 * recovered, robust.refine_before_px,
      robust.refine_after_px, robust.refined);
  EXPECT_GT(perfect - noisy, 1.0);  // the noise costs something: the test can fail
  EXPECT_GT(robust.refined, 30);
  EXPECT_LT(robust.refine_after_px, 0.5 * robust.refine_before_px);
  EXPECT_GT(robust_psnr, noisy - 0.5);
  EXPECT_GT(paper_psnr, noisy - 1.5);
}

}  // namespace
}  // namespace fresco
