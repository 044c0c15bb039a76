// The depth the movers' search rasterizes at full size and keeps for painting
// (MoverMaskOptions::full_size_depth, Frame::depth): the same depth painting's depth stage
// would rasterize, bit for bit; the movers it finds are those found from depth rasterized at
// the reduced size; painting takes it only at the pose it was rasterized at.
#include <cstdio>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "pipeline/paint/auto_modes.h"
#include "pipeline/paint/mover_masks.h"
#include "pipeline/render/rasterizer.h"
#include "pipeline/render/renderer.h"
#include "pipeline/synth/blocks_scene.h"
#include "pipeline/synth/synthesize.h"
#include "tests/paint/synth_session.h"

namespace fresco {
namespace {

bool SameBytes(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && a.isContinuous() && b.isContinuous() &&
         std::memcmp(a.data, b.data, a.total() * a.elemSize()) == 0;
}

struct Capture {
  Scene scene;
  SynthCapture capture;
};

Capture Orbit(int width, int height, int frames, int movers) {
  Capture c;
  BlocksOptions blocks;
  blocks.seed = 3;
  EXPECT_TRUE(MakeBlocksScene(blocks, &c.scene).ok());
  SynthOptions options = testing::BlocksHalfOrbit(blocks, frames, 11);
  options.width = width, options.height = height;
  options.random_movers = movers;
  EXPECT_TRUE(SynthesizeCapture(c.scene, options, &c.capture).ok());
  return c;
}

TEST(KeptDepth, TheMoversSearchKeepsTheDepthPaintingRasterizesAndFindsTheSameMovers) {
  const Capture c = Orbit(640, 480, 20, 2);
  MoverMaskOptions small_options;
  small_options.half_enough_below = 0;
  MoverMaskOptions full_options = small_options;
  full_options.full_size_depth = true;
  const MoverMaskResult small = testing::FindCaptureMovers(c.scene, c.capture, small_options);
  const MoverMaskResult full = testing::FindCaptureMovers(c.scene, c.capture, full_options);
  EXPECT_TRUE(small.depths.empty());
  ASSERT_EQ(full.depths.size(), c.capture.frames_bgr.size());
  const Rasterizer painting(c.capture.camera, RasterOptions());
  for (size_t i = 0; i < full.depths.size(); ++i) {
    cv::Mat depth;
    painting.RasterizeDepth(c.scene.mesh,
                            CamFromLocal(c.scene, c.capture.true_poses[i].cam_from_world), &depth);
    EXPECT_TRUE(SameBytes(full.depths[i], depth)) << "frame " << i;
  }
  long long pixels = 0, differ = 0, masked = 0;
  for (size_t i = 0; i < full.masks.size(); ++i) {
    ASSERT_EQ(full.masks[i].size(), small.masks[i].size());
    pixels += full.masks[i].total();
    masked += cv::countNonZero(small.masks[i]);
    differ += cv::countNonZero(full.masks[i] != small.masks[i]);
  }
  std::printf(
      "masked %lld of %lld pixels from the small depth, %lld differ; in regions %.4f "
      "against %.4f\n",
      masked, pixels, differ, full.compact_fraction(), small.compact_fraction());
  ASSERT_GT(masked, 2000);
  EXPECT_LT(differ, 0.05 * masked);
  EXPECT_GT(full.compact_fraction(), 2 * kBackgroundAcrossViewsThreshold);
  EXPECT_NEAR(full.compact_fraction(), small.compact_fraction(), 0.1 * small.compact_fraction());
}

// Paints the capture, each frame given `depth(i)` kept at `pose(i)`; the painted textures.
template <class DepthOf, class PoseOf>
std::vector<cv::Mat> PaintWithKeptDepth(const Capture& c, const DepthOf& depth_of,
                                        const PoseOf& pose_of) {
  PipelineOptions options;
  options.background.mode = BackgroundMode::kOff;
  options.refine.mode = RefineMode::kOff;
  std::unique_ptr<PaintSession> session = testing::SessionForCapture(c.scene, c.capture, options);
  FrameReport report;
  for (size_t i = 0; i < c.capture.frames_bgr.size(); ++i) {
    Frame frame;
    frame.index = static_cast<int>(i);
    frame.bgr = c.capture.frames_bgr[i];
    frame.depth = depth_of(i);
    frame.depth_cam_from_local = pose_of(i);
    session->PaintFrame(frame, c.capture.camera, c.capture.true_poses[i].cam_from_world, &report);
  }
  std::vector<cv::Mat> textures;
  for (const Texture& t : session->PaintedScene().textures) textures.push_back(t.rgba);
  return textures;
}

TEST(KeptDepth, PaintingTakesTheKeptDepthOnlyAtItsPose) {
  const Capture c = Orbit(320, 240, 6, 0);
  const Rasterizer rasterizer(c.capture.camera, RasterOptions());
  const auto pose = [&](size_t i) {
    return CamFromLocal(c.scene, c.capture.true_poses[i].cam_from_world);
  };
  const auto none = [](size_t) { return cv::Mat(); };
  const auto rasterized = [&](size_t i) {
    cv::Mat depth;
    rasterizer.RasterizeDepth(c.scene.mesh, pose(i), &depth);
    return depth;
  };
  // A wall 5 cm in front of the camera: everything behind it hidden.
  const auto wall = [&](size_t) {
    return cv::Mat(c.capture.camera.height, c.capture.camera.width, CV_32F, cv::Scalar(0.05));
  };
  const auto moved = [&](size_t i) {
    Rigid3d p = pose(i);
    p.translation.x() += 1e-9;
    return p;
  };
  const std::vector<cv::Mat> plain = PaintWithKeptDepth(c, none, pose);
  const std::vector<cv::Mat> kept = PaintWithKeptDepth(c, rasterized, pose);
  const std::vector<cv::Mat> walled = PaintWithKeptDepth(c, wall, pose);
  const std::vector<cv::Mat> elsewhere = PaintWithKeptDepth(c, wall, moved);
  ASSERT_FALSE(plain.empty());
  long long differ = 0;
  for (size_t t = 0; t < plain.size(); ++t) {
    EXPECT_TRUE(SameBytes(kept[t], plain[t])) << "texture " << t;
    EXPECT_TRUE(SameBytes(elsewhere[t], plain[t])) << "texture " << t;
    cv::Mat channels[4];
    cv::split(walled[t] != plain[t], channels);
    differ += cv::countNonZero(channels[0] | channels[1] | channels[2] | channels[3]);
  }
  EXPECT_GT(differ, 1000);  // the wall was taken: the scene behind it not painted
}

}  // namespace
}  // namespace fresco
