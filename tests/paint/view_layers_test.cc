// View-dependent layers (view_layers.h, view_dependent_render.h) against synthetic truth: an
// orbit whose first half sees the scene bright and second half dark (a direction-dependent
// look, as sun and haze give real photos) is rephotographed at frames left out of painting.
// One texture shows one look everywhere; the layers show each side its own.
#include <cmath>
#include <cstdio>
#include <set>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "pipeline/paint/paint_session.h"
#include "pipeline/paint/rephotography.h"
#include "pipeline/paint/view_layers.h"
#include "pipeline/render/view_dependent_render.h"
#include "pipeline/synth/blocks_scene.h"
#include "pipeline/synth/synthesize.h"
#include "tests/paint/synth_session.h"

namespace fresco {
namespace {

TEST(ViewLayers, FramesJoinTheLayerOfTheirDirectionAndLayersStaySpread) {
  ViewLayerOptions options;
  options.count = 2;
  options.min_angle_deg = 10;
  std::vector<ViewLayer> layers;
  const Eigen::Vector3d centre(1, 2, 3);
  const auto at_deg = [&](double deg) -> Eigen::Vector3d {
    const double a = deg * M_PI / 180;
    return centre + 4 * Eigen::Vector3d(std::cos(a), std::sin(a), 0);
  };
  const auto add = [&](const LayerChoice& choice, int frames) {
    if (choice.index == layers.size()) layers.emplace_back();
    layers[choice.index].direction = choice.direction;
    layers[choice.index].frames = frames;
  };
  // The first frame starts layer 0; 5 degrees away joins it; 30 degrees away starts layer 1.
  LayerChoice c = ChooseViewLayer(layers, centre, at_deg(0), options);
  EXPECT_TRUE(c.fresh);
  EXPECT_EQ(c.index, 0u);
  EXPECT_NEAR(c.direction.x(), 1.0, 1e-12);
  add(c, 3);
  c = ChooseViewLayer(layers, centre, at_deg(5), options);
  EXPECT_FALSE(c.fresh);
  EXPECT_EQ(c.index, 0u);
  c = ChooseViewLayer(layers, centre, at_deg(30), options);
  EXPECT_TRUE(c.fresh);
  EXPECT_EQ(c.index, 1u);
  add(c, 1);
  // Full: a frame at 45 degrees is nearer layer 1 (15 degrees) than the two layers are to each
  // other (30): it joins; at 120 degrees the layer with fewer frames of the nearest pair (1)
  // makes way for it.
  c = ChooseViewLayer(layers, centre, at_deg(45), options);
  EXPECT_FALSE(c.fresh);
  EXPECT_EQ(c.index, 1u);
  c = ChooseViewLayer(layers, centre, at_deg(120), options);
  EXPECT_TRUE(c.fresh);
  EXPECT_EQ(c.index, 1u);
}

// The blocks orbit (half a turn, 36 frames): with two looks, frames 0-17 at gain 1.3, 18-35 at
// gain 0.7; otherwise as rendered (one look: the figure the layers should come near).
struct TwoLookCapture {
  Scene scene;
  SynthCapture capture;
  std::set<int> held_out = {4, 13, 22, 31};
};

TwoLookCapture MakeTwoLookCapture(bool two_looks) {
  TwoLookCapture c;
  BlocksOptions blocks;
  blocks.seed = 5;
  EXPECT_TRUE(MakeBlocksScene(blocks, &c.scene).ok());
  EXPECT_TRUE(SynthesizeCapture(c.scene, testing::BlocksHalfOrbit(blocks, 36, 9), &c.capture).ok());
  for (size_t i = 0; two_looks && i < c.capture.frames_bgr.size(); ++i)
    c.capture.frames_bgr[i].convertTo(c.capture.frames_bgr[i], CV_8UC3, i < 18 ? 1.3 : 0.7);
  return c;
}

// Paints every frame but the held-out ones; the rephoto PSNR at each held-out frame.
std::vector<double> HeldOutPsnr(const TwoLookCapture& c, const PipelineOptions& options,
                                size_t* layers) {
  std::unique_ptr<PaintSession> session = testing::SessionForCapture(c.scene, c.capture, options);
  FrameReport report;
  for (size_t i = 0; i < c.capture.frames_bgr.size(); ++i)
    if (!c.held_out.count(static_cast<int>(i)))
      testing::PaintCaptureFrame(session.get(), c.capture, i, &report);
  *layers = session->view_layers().size();
  const Scene base = session->PaintedScene();
  const std::vector<ViewLayerScene> layer_scenes = session->LayerScenes();
  const Renderer renderer(c.capture.camera, RenderOptions());
  std::vector<double> psnr;
  for (int i : c.held_out) {
    RenderOutput out;
    RenderViewDependent(renderer, base, layer_scenes, c.capture.true_poses[i].cam_from_world, &out);
    RephotoView view;
    psnr.push_back(ScoreRendered(out, c.capture.frames_bgr[i], &view).psnr_db);
  }
  return psnr;
}

TEST(ViewLayers, EachSideOfAnOrbitKeepsItsOwnLook) {
  const TwoLookCapture c = MakeTwoLookCapture(true);
  PipelineOptions one;
  one.background.mode = BackgroundMode::kOff;
  one.refine.mode = RefineMode::kOff;
  PipelineOptions layered = one;
  layered.layers.count = 8;
  layered.layers.min_angle_deg = 10;
  size_t n_one = 0, n_layered = 0;
  const std::vector<double> single = HeldOutPsnr(c, one, &n_one);
  const std::vector<double> views = HeldOutPsnr(c, layered, &n_layered);
  size_t n_unused = 0;
  const std::vector<double> one_look = HeldOutPsnr(MakeTwoLookCapture(false), one, &n_unused);
  EXPECT_EQ(n_one, 0u);
  EXPECT_GE(n_layered, 4u);  // half a turn in 10-degree steps, up to 8
  EXPECT_LE(n_layered, 8u);
  for (size_t k = 0; k < single.size(); ++k) {
    std::printf(
        "held-out frame %d: one texture %.2f dB, %zu layers %.2f dB (frames of one look, one "
        "texture: %.2f dB)\n",
        *std::next(c.held_out.begin(), static_cast<long>(k)), single[k], n_layered, views[k],
        one_look[k]);
    // The same errors at a gain g change the PSNR by -20 log10(g): the figure the layers would
    // reach if they reproduced each side's look exactly. Views beside the step from bright to
    // dark blend a layer of the other look (the step is abrupt here; real looks change
    // smoothly): within 2 dB of it.
    const int frame = *std::next(c.held_out.begin(), static_cast<long>(k));
    const double ideal = one_look[k] - 20 * std::log10(frame < 18 ? 1.3 : 0.7);
    EXPECT_GT(views[k], single[k] + 5.0);
    EXPECT_GT(views[k], ideal - 2.0);
  }
}

}  // namespace
}  // namespace fresco
