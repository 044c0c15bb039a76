// The exposure and select stages (exposure_gain.h, view_select.h) against synthetic truth: a
// capture whose frames change exposure paints one consistent texture (the first frame's
// mean exposure) when the gain is divided out, and depth discontinuities are found where the depth
// map jumps.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/image_metrics.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/paint/view_select.h"
#include "pipeline/render/renderer.h"
#include "pipeline/synth/blocks_scene.h"
#include "pipeline/synth/synthesize.h"
#include "tests/paint/rephotograph.h"
#include "tests/paint/room_capture.h"
#include "tests/paint/synth_session.h"

namespace fresco {
namespace {

// Mean PSNR of the painted model against the true scene with exposure `gain`, at the true
// poses of frames `frames`, where both show a painted surface.
double MeanPsnrAgainstTruth(const Scene& truth, const Scene& painted, const SynthCapture& capture,
                            double gain, const std::vector<int>& frames) {
  RenderOptions options;
  options.raster.supersample = 2;
  const Renderer renderer(capture.camera, options);
  double sum = 0;
  for (int i : frames) {
    testing::TruthAndPainted r = testing::RenderTruthAndPainted(
        renderer, truth, painted, capture.true_poses[i].cam_from_world);
    r.truth_bgr.convertTo(r.truth_bgr, CV_8UC3, gain);
    sum += PsnrDb(r.truth_bgr, r.painted_bgr, r.both);
  }
  return sum / frames.size();
}

TEST(ViewSelect, DepthEdgesAtJumpsAndSilhouettes) {
  cv::Mat depth(40, 60, CV_32F, cv::Scalar(2.0f));
  depth(cv::Rect(30, 0, 30, 40)).setTo(2.5f);  // a 25 % jump at x = 29 | 30
  depth(cv::Rect(0, 0, 60, 5)).setTo(std::numeric_limits<float>::infinity());  // sky above
  const cv::Mat d = DistanceToDepthEdges(depth, 0.05);
  EXPECT_LT(d.at<float>(20, 29), 0.5f);
  EXPECT_LT(d.at<float>(20, 30), 0.5f);
  EXPECT_NEAR(d.at<float>(20, 20), 9.0f, 0.5f);
  EXPECT_LT(d.at<float>(5, 10), 0.5f);  // the silhouette against no surface
  EXPECT_NEAR(d.at<float>(12, 10), 7.0f, 0.5f);
  // A gentle slope is no discontinuity.
  cv::Mat slope(40, 60, CV_32F);
  for (int x = 0; x < 60; ++x) slope.col(x).setTo(2.0f + 0.01f * x);
  EXPECT_GT(DistanceToDepthEdges(slope, 0.05).at<float>(20, 30), 15.0f);
}

TEST(ViewSelect, ExposureChangesPaintOneConsistentTexture) {
  const Scene scene = testing::RoomScene();
  SynthOptions o = testing::HandheldRoomCapture(24, 0.8);
  o.seed = 3;
  o.exposure_jitter = 0.25;
  SynthCapture capture;
  ASSERT_TRUE(SynthesizeCapture(scene, o, &capture).ok());
  // The frames' gains vary by tens of percent: the truth for a consistent texture is the
  // frames' mean exposure (geometric), which the painted scene takes.
  const auto [lo, hi] =
      std::minmax_element(capture.exposure_gains.begin(), capture.exposure_gains.end());
  ASSERT_GT(*hi / *lo, 1.3);
  double log_sum = 0;
  for (double g : capture.exposure_gains) log_sum += std::log(g);
  const double g0 = std::exp(log_sum / capture.exposure_gains.size());
  const std::vector<int> views = {0, 6, 12, 18, 23};

  PipelineOptions off;
  off.background.mode = BackgroundMode::kOff;  // the gain alone, not the background model's
  off.refine.mode = RefineMode::kOff;
  off.select.enabled = false;
  off.update = UpdatePolicy::kQuality;  // the sharpest view per texel, as selection keeps one
  PipelineOptions no_exposure = off;
  no_exposure.select.enabled = true;
  no_exposure.select.exposure = false;
  PipelineOptions with = no_exposure;
  with.select.exposure = true;
  const double psnr_off =
      MeanPsnrAgainstTruth(scene, testing::PaintAllFrames(scene, capture, off), capture, g0, views);
  const double psnr_no_exposure = MeanPsnrAgainstTruth(
      scene, testing::PaintAllFrames(scene, capture, no_exposure), capture, g0, views);
  const double psnr_with = MeanPsnrAgainstTruth(
      scene, testing::PaintAllFrames(scene, capture, with), capture, g0, views);
  std::printf(
      "truth PSNR at the frames' mean exposure: select off %.2f, no exposure %.2f, "
      "with exposure %.2f dB\n",
      psnr_off, psnr_no_exposure, psnr_with);
  EXPECT_GT(psnr_with, psnr_off + 8.0);
  EXPECT_GT(psnr_with, psnr_no_exposure + 5.0);
  EXPECT_GT(psnr_with, 28.0);
}

// What real data looks like: the frames see the true boxes with changing exposure, the mesh
// painted is the same boxes moved 5 cm sideways (a few pixels at these distances), so near
// every silhouette frames sample what lies behind. Scored as a user can (rephotography: the
// painted mesh rendered at frame poses against the frames, mean PSNR and local 1 - NCC).
struct DisplacedBoxes {
  Scene truth, mesh;
  SynthCapture capture;
  SynthCapture painting;  // the same frames at the given (noisy) poses

  explicit DisplacedBoxes(double pose_noise_deg = 0) {
    BlocksOptions blocks;
    blocks.seed = 3;
    EXPECT_TRUE(MakeBlocksScene(blocks, &truth).ok());
    mesh = truth;
    for (Eigen::Vector3d& v : mesh.mesh.vertices)
      if (v.y() > 1e-6) v += Eigen::Vector3d(0.05, 0, 0.0);  // the boxes; the ground stays
    SynthOptions o = testing::BlocksHalfOrbit(blocks, 30, 7);
    o.exposure_jitter = 0.2;
    o.pose_noise_deg = pose_noise_deg;
    EXPECT_TRUE(SynthesizeCapture(truth, o, &capture).ok());
    painting = capture;
    painting.true_poses = capture.given_poses;
  }

  // Mean PSNR (returned) and 1 - NCC at five of the frames.
  double Score(const PipelineOptions& options, double* ncc) const {
    const Scene painted = testing::PaintAllFrames(mesh, painting, options);
    const Renderer renderer(capture.camera, RenderOptions());
    double psnr = 0;
    *ncc = 0;
    const std::vector<int> views = {2, 9, 16, 23, 28};
    for (int i : views) {
      RenderOutput out;
      renderer.Render(painted, capture.true_poses[i].cam_from_world, &out);
      std::vector<cv::Mat> ch;
      cv::split(out.rgba, ch);
      const cv::Mat painted_px = ch[3] == 255;
      cv::Mat bgr;
      cv::cvtColor(out.rgba, bgr, cv::COLOR_RGBA2BGR);
      psnr += PsnrDb(capture.frames_bgr[i], bgr, painted_px) / views.size();
      *ncc += LocalOneMinusNcc(capture.frames_bgr[i], bgr, painted_px) / views.size();
    }
    return psnr;
  }
};

TEST(ViewSelect, DisplacedMeshAndExposureChanges) {
  const DisplacedBoxes boxes;
  PipelineOptions off;  // the robust background model, no refinement
  off.background.mode = BackgroundMode::kRobust;
  off.refine.mode = RefineMode::kOff;
  off.select.enabled = false;
  PipelineOptions on = off;
  on.select.enabled = true;
  double ncc_off = 0, ncc_on = 0;
  const double psnr_off = boxes.Score(off, &ncc_off);
  const double psnr_on = boxes.Score(on, &ncc_on);
  // The edge penalty alone: the robust background model also rejects most background
  // sampled past a silhouette (a minority of a texel's samples), so it shows without it.
  PipelineOptions no_model = on;
  no_model.background.mode = BackgroundMode::kOff;
  PipelineOptions no_model_no_edges = no_model;
  no_model_no_edges.select.edge_px = 0;
  double ncc_edges = 0, ncc_no_edges = 0;
  const double psnr_edges = boxes.Score(no_model, &ncc_edges);
  const double psnr_no_edges = boxes.Score(no_model_no_edges, &ncc_no_edges);
  std::printf(
      "displaced boxes, exposure changes: select off %.2f dB / 1-NCC %.3f, on "
      "%.2f / %.3f; background off: edge penalty off %.2f / %.3f, on %.2f / %.3f\n",
      psnr_off, ncc_off, psnr_on, ncc_on, psnr_no_edges, ncc_no_edges, psnr_edges, ncc_edges);
  EXPECT_GT(psnr_on, psnr_off + 1.0);
  EXPECT_LT(ncc_on, ncc_off - 0.03);
  EXPECT_GT(psnr_edges, psnr_no_edges + 0.3);
  EXPECT_LT(ncc_edges, ncc_no_edges - 0.005);
}

// `update: mean` on the same capture: every view averaged (weighted by pixels per texel) against
// the best view kept per texel with its exposure matched; and with the given poses 0.3 deg
// off (frames that disagree by a few pixels, as real photos do): blended, not interleaved.
TEST(ViewSelect, TheMeanOfEveryViewOnADisplacedMeshAndNoisyPoses) {
  PipelineOptions automatic;  // the default update, no background model, no refinement
  automatic.background.mode = BackgroundMode::kOff;
  automatic.refine.mode = RefineMode::kOff;
  PipelineOptions quality = automatic;
  quality.update = UpdatePolicy::kQuality;
  PipelineOptions select = quality;
  select.select.enabled = true;
  PipelineOptions mean = quality;
  mean.update = UpdatePolicy::kMean;
  for (const double noise_deg : {0.0, 0.3}) {
    const DisplacedBoxes boxes(noise_deg);
    double ncc_quality = 0, ncc_select = 0, ncc_mean = 0, ncc_auto = 0;
    const double psnr_quality = boxes.Score(quality, &ncc_quality);
    const double psnr_select = boxes.Score(select, &ncc_select);
    const double psnr_mean = boxes.Score(mean, &ncc_mean);
    const double psnr_auto = boxes.Score(automatic, &ncc_auto);
    std::printf(
        "displaced boxes, exposure changes, pose noise %.1f deg: quality %.2f dB / 1-NCC %.3f, "
        "select %.2f / %.3f, mean %.2f / %.3f, auto %.2f / %.3f\n",
        noise_deg, psnr_quality, ncc_quality, psnr_select, ncc_select, psnr_mean, ncc_mean,
        psnr_auto, ncc_auto);
    // `auto` (the default) as good as the better of the two it decides between.
    EXPECT_GT(psnr_auto, std::max(psnr_quality, psnr_mean) - 0.2);
    if (noise_deg == 0) {
      EXPECT_GT(psnr_mean, psnr_select - 0.3);
      EXPECT_LT(ncc_mean, ncc_select + 0.005);
    } else {
      EXPECT_GT(psnr_mean, psnr_select + 2.0);
      EXPECT_GT(psnr_mean, psnr_quality + 1.0);
      EXPECT_LT(ncc_mean, ncc_select - 0.1);
    }
  }
}

}  // namespace
}  // namespace fresco
