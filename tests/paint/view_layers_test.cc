// View-dependent layers (view_layers.h, view_dependent_render.h) against synthetic truth: an
// orbit whose first half sees the scene bright and second half dark (a direction-dependent
// look, as sun and haze give real photos) is rephotographed at frames left out of painting.
// One texture shows one look everywhere; the layers show each side its own.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <set>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "pipeline/core/image_metrics.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/paint/rephotography.h"
#include "pipeline/paint/view_layers.h"
#include "pipeline/render/view_dependent_render.h"
#include "pipeline/synth/blocks_scene.h"
#include "pipeline/synth/synthesize.h"
#include "tests/paint/synth_session.h"
#include "tests/test_support.h"

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
// `painted_out`: the painted scene (when not null).
std::vector<double> HeldOutPsnr(const TwoLookCapture& c, const PipelineOptions& options,
                                size_t* layers, Scene* painted_out = nullptr) {
  std::unique_ptr<PaintSession> session = testing::SessionForCapture(c.scene, c.capture, options);
  FrameReport report;
  for (size_t i = 0; i < c.capture.frames_bgr.size(); ++i)
    if (!c.held_out.count(static_cast<int>(i)))
      testing::PaintCaptureFrame(session.get(), c.capture, i, &report);
  *layers = session->view_layers().size();
  const Scene painted = session->PaintedScene();
  if (painted_out) *painted_out = painted;
  const Renderer renderer(c.capture.camera, RenderOptions());
  std::vector<double> psnr;
  for (int i : c.held_out) {
    RephotoView view;
    psnr.push_back(ScoreRephoto(renderer, painted, c.capture.true_poses[i].cam_from_world,
                                c.capture.frames_bgr[i], &view)
                       .psnr_db);
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
    // The single texture: `update: auto`'s sharp mean (17.44 dB at frame 4; its plain mean
    // 17.18): layers keep the sharpest view or the mean, and give the same 22.25 dB as before.
    EXPECT_GT(views[k], single[k] + 4.75);
    EXPECT_GT(views[k], ideal - 2.0);
  }
}

// painted.gltf keeps the layers (the FRESCO_view_layers extension): loaded back, the model
// renders as it did before it was written, and a viewer without layers sees the base texture.
TEST(ViewLayers, LayersSurviveTheGltfRoundTrip) {
  const TwoLookCapture c = MakeTwoLookCapture(true);
  PipelineOptions layered;
  layered.background.mode = BackgroundMode::kOff;
  layered.refine.mode = RefineMode::kOff;
  layered.layers.count = 4;
  size_t n = 0;
  Scene painted;
  HeldOutPsnr(c, layered, &n, &painted);
  ASSERT_EQ(painted.view_layers.size(), n);
  ASSERT_GE(n, 2u);
  const std::string path = testing::MakeTempDir("view_layers") + "/painted.gltf";
  ASSERT_TRUE(SaveGltfScene(painted, path).ok());
  Scene loaded;
  const Status status = LoadGltfScene(path, SceneLoadOptions(), &loaded);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_TRUE(loaded.warnings.empty()) << loaded.warnings.front();
  ASSERT_EQ(loaded.view_layers.size(), n);
  for (size_t k = 0; k < n; ++k) {
    EXPECT_LT((loaded.view_layers[k].centre_world - painted.view_layers[k].centre_world).norm(),
              1e-9);
    EXPECT_EQ(loaded.view_layers[k].material_texture.size(), loaded.materials.size());
  }
  // A malformed extension (a texture list of the wrong length) loads the model without layers,
  // with a warning naming the field.
  {
    std::ifstream in(path);
    std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string key = "\"textures\": [";
    const size_t at = json.find(key, json.find("\"FRESCO_view_layers\": {"));
    ASSERT_NE(at, std::string::npos);
    json.insert(at + key.size(), "-1, ");
    std::ofstream(path) << json;
    Scene broken;
    ASSERT_TRUE(LoadGltfScene(path, SceneLoadOptions(), &broken).ok());
    EXPECT_TRUE(broken.view_layers.empty());
    ASSERT_EQ(broken.warnings.size(), 1u);
    EXPECT_NE(broken.warnings[0].find("FRESCO_view_layers: layers[0]"), std::string::npos)
        << broken.warnings[0];
  }
  const Renderer renderer(c.capture.camera, RenderOptions());
  for (int i : {4, 31}) {
    RenderOutput before, after, single;
    RenderViewDependent(renderer, painted, c.capture.true_poses[i].cam_from_world, &before);
    RenderViewDependent(renderer, loaded, c.capture.true_poses[i].cam_from_world, &after);
    renderer.Render(loaded, c.capture.true_poses[i].cam_from_world, &single);
    const cv::Mat both = cv::Mat(before.triangle_id >= 0) & cv::Mat(after.triangle_id >= 0);
    EXPECT_GT(PsnrDb(before.rgba, after.rgba, both), 45.0);
    // The base texture alone differs from the blend (frame 4 is on the bright side).
    EXPECT_LT(PsnrDb(before.rgba, single.rgba, both), 30.0);
  }
}

}  // namespace
}  // namespace fresco
