// Painting during the warp (frame_warp.h WarpAndPaintBuffer, taken when no stage looks at the
// warped samples before the paint stage) paints exactly what the two stages paint one after
// the other: the same texels, colours, stored qualities and figures, bit for bit, for every
// sampling mode, every update policy (with the sums `mean` and `auto` keep), a running average
// and a distorted lens.
#include <gtest/gtest.h>
#include <algorithm>
#include <limits>
#include <opencv2/core.hpp>

#include "pipeline/paint/frame_warp.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/synth/blocks_scene.h"
#include "pipeline/synth/procedural_scenes.h"
#include "pipeline/synth/synthesize.h"
#include "tests/paint/room_capture.h"
#include "tests/paint/synth_session.h"

namespace fresco {
namespace {

struct Painted {
  std::vector<PaintedBuffer> buffers;
  std::vector<FrameReport> reports;
};

// Debug images make the session keep the two stages apart (the warped samples are shown);
// without them, with no background model and no refinement, it paints during the warp.
Painted Paint(const Scene& scene, const SynthCapture& capture, const PipelineOptions& options,
              bool separate_stages) {
  std::unique_ptr<PaintSession> session = testing::SessionForCapture(scene, capture, options);
  session->set_debug_images(separate_stages);
  Painted out;
  for (size_t i = 0; i < capture.frames_bgr.size(); ++i) {
    FrameReport report;
    testing::PaintCaptureFrame(session.get(), capture, i, &report);
    out.reports.push_back(report);
  }
  out.buffers = session->painted();
  return out;
}

// No stage between the warp and the paint stage (no background model, refinement, exposure
// or view selection): the case in which the warp paints.
PipelineOptions NoStageBetween() {
  PipelineOptions options;
  options.background.mode = BackgroundMode::kOff;
  options.refine.mode = RefineMode::kOff;
  options.select.enabled = false;
  return options;
}

void ExpectSame(const Painted& a, const Painted& b, const std::string& what) {
  ASSERT_EQ(a.buffers.size(), b.buffers.size());
  long long painted_texels = 0;
  for (size_t k = 0; k < a.buffers.size(); ++k) {
    EXPECT_EQ(cv::norm(a.buffers[k].bgra, b.buffers[k].bgra, cv::NORM_INF), 0) << what << " b" << k;
    EXPECT_EQ(cv::norm(a.buffers[k].quality, b.buffers[k].quality, cv::NORM_INF), 0)
        << what << " b" << k;
    EXPECT_EQ(a.buffers[k].painted_surface_texels, b.buffers[k].painted_surface_texels) << what;
    const auto same_or_both_empty = [&](const cv::Mat& x, const cv::Mat& y, const char* name) {
      ASSERT_EQ(x.empty(), y.empty()) << what << " b" << k << " " << name;
      if (!x.empty())
        EXPECT_EQ(cv::norm(x, y, cv::NORM_INF), 0) << what << " b" << k << " " << name;
    };
    same_or_both_empty(a.buffers[k].mean_sum, b.buffers[k].mean_sum, "mean_sum");
    same_or_both_empty(a.buffers[k].shadow_bgra, b.buffers[k].shadow_bgra, "shadow_bgra");
    same_or_both_empty(a.buffers[k].shadow_quality, b.buffers[k].shadow_quality, "shadow_quality");
    same_or_both_empty(a.buffers[k].held_sum, b.buffers[k].held_sum, "held_sum");
    painted_texels += a.buffers[k].painted_surface_texels;
  }
  EXPECT_GT(painted_texels, 10000) << what;  // the capture paints the room
  ASSERT_EQ(a.reports.size(), b.reports.size());
  for (size_t i = 0; i < a.reports.size(); ++i) {
    const StageReport* pa = a.reports[i].Stage("paint");
    const StageReport* pb = b.reports[i].Stage("paint");
    ASSERT_TRUE(pa && pb);
    for (const char* m : {"texels_written", "texels_kept_sharper", "coverage"})
      EXPECT_EQ(pa->metrics.at(m), pb->metrics.at(m)) << what << " frame " << i << " " << m;
    const double da = a.reports[i].paint.difference_to_buffer;
    const double db = b.reports[i].paint.difference_to_buffer;
    EXPECT_TRUE(da == db || (std::isnan(da) && std::isnan(db))) << what << " frame " << i;
    EXPECT_EQ(a.reports[i].Stage("warp")->metrics.at("texels_visible"),
              b.reports[i].Stage("warp")->metrics.at("texels_visible"));
  }
}

TEST(PaintInWarp, PaintsWhatTheTwoStagesPaint) {
  CubeRoomOptions room;
  room.procedural_texture_px = 256;
  Scene scene;
  ASSERT_TRUE(MakeCubeRoomScene(room, &scene).ok());
  for (const LensModel lens : {LensModel::kPinhole, LensModel::kOpenCV8}) {
    SynthOptions synth = testing::HandheldRoomCapture(8, 0.8);
    synth.width = 160, synth.height = 120;
    synth.lens = lens;
    synth.seed = 5;
    SynthCapture capture;
    ASSERT_TRUE(SynthesizeCapture(scene, synth, &capture).ok());
    PipelineOptions options = NoStageBetween();
    for (const SamplingMode sampling :
         {SamplingMode::kNearest, SamplingMode::kBilinear, SamplingMode::kArea}) {
      options.sampling = sampling;
      for (const UpdatePolicy policy : {UpdatePolicy::kQuality, UpdatePolicy::kLatest,
                                        UpdatePolicy::kMean, UpdatePolicy::kAuto}) {
        options.update = policy;
        for (const double weight : {1.0, 0.3}) {
          options.update_weight = weight;
          const std::string what = "lens " + std::to_string(static_cast<int>(lens)) +
                                   " sampling " + std::to_string(static_cast<int>(sampling)) +
                                   " policy " + std::to_string(static_cast<int>(policy)) +
                                   " weight " + std::to_string(weight);
          const Painted fused = Paint(scene, capture, options, false);
          const Painted separate = Paint(scene, capture, options, true);
          EXPECT_EQ(fused.reports[0].Stage("paint")->notes.count("painted"), 1u) << what;
          EXPECT_EQ(separate.reports[0].Stage("paint")->notes.count("painted"), 0u) << what;
          ExpectSame(fused, separate, what);
        }
      }
    }
  }
}

// Boxes on a ground seen from an orbit: boxes hide one another and the ground, so the
// occlusion test decides (painting during the warp reads each pixel's 2x2 depth range,
// the separate warp the four depths: the same test).
TEST(PaintInWarp, PaintsWhatTheTwoStagesPaintWhereBoxesHideEachOther) {
  BlocksOptions blocks;
  blocks.seed = 3;
  Scene scene;
  ASSERT_TRUE(MakeBlocksScene(blocks, &scene).ok());
  for (const LensModel lens : {LensModel::kPinhole, LensModel::kOpenCV8}) {
    SynthOptions o;
    o.frames = 6;
    o.width = 160, o.height = 120;
    o.lens = lens;
    o.path = CameraPathKind::kOrbit;
    o.target = Eigen::Vector3d(0, 0.3 * blocks.max_height_m, 0);
    o.radius_m = 0.6 * blocks.ground_m;
    o.height_m = 0.3 * blocks.ground_m;
    o.turns = 0.3;
    o.seed = 7;
    SynthCapture capture;
    ASSERT_TRUE(SynthesizeCapture(scene, o, &capture).ok());
    PipelineOptions options = NoStageBetween();
    const Painted fused = Paint(scene, capture, options, false);
    const Painted separate = Paint(scene, capture, options, true);
    double occluded = 0;
    for (const FrameReport& r : fused.reports)
      occluded += r.Stage("warp")->metrics.at("texels_occluded");
    EXPECT_GT(occluded, 1000) << "lens " << static_cast<int>(lens) << ": nothing hidden";
    ExpectSame(fused, separate, "blocks, lens " + std::to_string(static_cast<int>(lens)));
  }
}

// The 2x2 range against the four depths, with pixels where nothing was hit (infinite).
TEST(DepthRange2x2, LeastAndGreatestOfEachTwoByTwoBlock) {
  cv::Mat depth(7, 9, CV_32F);
  cv::RNG rng(3);
  rng.fill(depth, cv::RNG::UNIFORM, 0.5, 9.0);
  depth.at<float>(2, 3) = std::numeric_limits<float>::infinity();
  depth.at<float>(6, 8) = std::numeric_limits<float>::infinity();
  cv::Mat range;
  DepthRange2x2(depth, &range);
  ASSERT_EQ(range.type(), CV_32FC2);
  ASSERT_EQ(range.size(), depth.size());
  for (int y = 0; y < depth.rows; ++y)
    for (int x = 0; x < depth.cols; ++x) {
      const int x1 = std::min(x + 1, depth.cols - 1), y1 = std::min(y + 1, depth.rows - 1);
      const float d[4] = {depth.at<float>(y, x), depth.at<float>(y, x1), depth.at<float>(y1, x),
                          depth.at<float>(y1, x1)};
      EXPECT_EQ(range.at<cv::Vec2f>(y, x)[0], *std::min_element(d, d + 4)) << x << "," << y;
      EXPECT_EQ(range.at<cv::Vec2f>(y, x)[1], *std::max_element(d, d + 4)) << x << "," << y;
    }
  EXPECT_TRUE(std::isinf(range.at<cv::Vec2f>(2, 2)[1]));  // the block holding (3, 2)
  EXPECT_FALSE(std::isinf(range.at<cv::Vec2f>(2, 2)[0]));
}

}  // namespace
}  // namespace fresco
