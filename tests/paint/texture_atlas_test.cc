// The texture atlas: packing (no overlaps, aligned, within the pages), padding, and the
// painted model exported through atlas pages renders like the per-buffer painting, with no
// bleeding between buffers at their borders.
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/image_metrics.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/paint/texture_atlas.h"
#include "pipeline/render/renderer.h"
#include "pipeline/synth/procedural_scenes.h"
#include "pipeline/synth/synthesize.h"
#include "tests/paint/room_capture.h"

namespace fresco {
namespace {

TEST(TextureAtlas, PacksWithoutOverlapAlignedAndWithinPages) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> side(1, 300);
  std::vector<cv::Size> sizes;
  for (int i = 0; i < 400; ++i) sizes.emplace_back(side(rng), side(rng));
  sizes.emplace_back(0, 0);  // an empty buffer takes no place
  AtlasOptions options;
  options.page_size = 1024;
  options.padding_texels = 3;
  TextureAtlas atlas;
  ASSERT_TRUE(PackAtlas(sizes, options, &atlas).ok());
  EXPECT_EQ(atlas.alignment, 4);
  EXPECT_GE(atlas.pages.size(), 2u);
  EXPECT_LE(atlas.pages.size(), 16u);
  EXPECT_EQ(atlas.placements.back().page, -1);
  std::vector<cv::Mat> used;
  for (const cv::Size& page : atlas.pages) {
    EXPECT_LE(page.width, options.page_size);
    EXPECT_LE(page.height, options.page_size);
    used.push_back(cv::Mat::zeros(page, CV_8U));
  }
  long long texels = 0;
  for (size_t b = 0; b + 1 < sizes.size(); ++b) {
    const AtlasPlacement& p = atlas.placements[b];
    ASSERT_GE(p.page, 0) << b;
    // The padded rectangle starts on the alignment and lies inside its page.
    const cv::Rect padded(p.x - 3, p.y - 3, sizes[b].width + 6, sizes[b].height + 6);
    EXPECT_EQ(padded.x % 4, 0);
    EXPECT_EQ(padded.y % 4, 0);
    ASSERT_TRUE((padded & cv::Rect(cv::Point(), atlas.pages[p.page])) == padded) << b;
    // No two padded rectangles share a texel.
    EXPECT_EQ(cv::countNonZero(used[p.page](padded)), 0) << b;
    used[p.page](padded).setTo(1);
    texels += sizes[b].area();
  }
  EXPECT_EQ(atlas.used_texels, texels);
  EXPECT_GT(atlas.Occupancy(), 0.4);
}

// A shard's part holds some buffers' placements in strips (ComposeAtlasStrip); put back at
// StripPositions, every part's strip makes the page ComposeAtlasPage makes.
TEST(TextureAtlas, StripsOfEveryBufferPutBackMakeThePage) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> side(1, 120), value(0, 255);
  std::vector<cv::Mat> images;
  std::vector<cv::Size> sizes;
  for (int i = 0; i < 60; ++i) {
    images.emplace_back(side(rng), side(rng), CV_8UC4);
    cv::randu(images.back(), 0, 256);
    sizes.push_back(images.back().size());
  }
  AtlasOptions options;
  options.page_size = 512;
  options.padding_texels = 2;
  TextureAtlas atlas;
  ASSERT_TRUE(PackAtlas(sizes, options, &atlas).ok());
  ASSERT_GE(atlas.pages.size(), 2u);
  for (int page = 0; page < static_cast<int>(atlas.pages.size()); ++page) {
    cv::Mat joined = cv::Mat::zeros(atlas.pages[page], CV_8UC4);
    for (int part = 0; part < 3; ++part) {  // buffer b in part b % 3
      std::vector<bool> which(images.size());
      std::vector<cv::Rect> rects;
      std::vector<cv::Size> rect_sizes;
      for (size_t b = 0; b < images.size(); ++b) {
        which[b] = static_cast<int>(b % 3) == part;
        if (!which[b] || atlas.placements[b].page != page) continue;
        rects.push_back(PaddedPlacement(atlas, b, sizes[b]));
        rect_sizes.push_back(rects.back().size());
      }
      const cv::Mat strip = ComposeAtlasStrip(atlas, page, images, which);
      cv::Size strip_size;
      const std::vector<cv::Point> at =
          StripPositions(rect_sizes, atlas.pages[page].width, &strip_size);
      ASSERT_EQ(strip.size(), strip_size);
      for (size_t k = 0; k < rects.size(); ++k)
        strip(cv::Rect(at[k], rects[k].size())).copyTo(joined(rects[k]));
    }
    const cv::Mat whole = ComposeAtlasPage(atlas, page, images);
    EXPECT_EQ(cv::norm(joined, whole, cv::NORM_INF), 0.0) << "page " << page;
  }
}

TEST(TextureAtlas, RefusesABufferLargerThanAPage) {
  AtlasOptions options;
  options.page_size = 256;
  options.padding_texels = 4;
  EXPECT_EQ(MaxBufferSide(options), 248);
  TextureAtlas atlas;
  EXPECT_TRUE(PackAtlas({cv::Size(248, 248)}, options, &atlas).ok());
  const Status s = PackAtlas({cv::Size(10, 10), cv::Size(249, 8)}, options, &atlas);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("base buffer 1 is 249x8"), std::string::npos) << s.message();
}

TEST(TextureAtlas, PaddingRepeatsTheEdgeTexels) {
  AtlasOptions options;
  options.page_size = 256;
  options.padding_texels = 2;
  cv::Mat a(3, 5, CV_8UC4), b(4, 2, CV_8UC4);
  cv::randu(a, 0, 256);
  cv::randu(b, 0, 256);
  TextureAtlas atlas;
  ASSERT_TRUE(PackAtlas({a.size(), b.size()}, options, &atlas).ok());
  const cv::Mat page = ComposeAtlasPage(atlas, 0, {a, b});
  for (int i = 0; i < 2; ++i) {
    const cv::Mat& image = i == 0 ? a : b;
    const AtlasPlacement& p = atlas.placements[i];
    for (int y = -2; y < image.rows + 2; ++y)
      for (int x = -2; x < image.cols + 2; ++x) {
        const cv::Vec4b expected = image.at<cv::Vec4b>(std::clamp(y, 0, image.rows - 1),
                                                       std::clamp(x, 0, image.cols - 1));
        ASSERT_EQ(page.at<cv::Vec4b>(p.y + y, p.x + x), expected) << i << " " << x << "," << y;
      }
  }
}

// The room painted with every triangle in a buffer of its own (charts meeting along each
// face's diagonal) onto small pages, so that buffers of one face land on different pages.
TEST(TextureAtlas, AtlasExportRendersLikeThePerBufferPainting) {
  CubeRoomOptions room;
  room.procedural_texture_px = 256;
  Scene scene;
  ASSERT_TRUE(MakeCubeRoomScene(room, &scene).ok());
  SynthOptions synth = testing::HandheldRoomCapture(10, 0.8);
  synth.seed = 5;
  SynthCapture capture;
  ASSERT_TRUE(SynthesizeCapture(scene, synth, &capture).ok());
  PaintSessionInputs inputs;
  inputs.scene = &scene;
  inputs.pipeline.texel_size_m = 0.02;
  inputs.pipeline.background.mode = BackgroundMode::kOff;
  inputs.pipeline.atlas.page_size = 512;
  inputs.pipeline.atlas.padding_texels = 2;
  for (int t = 0; t < scene.mesh.NumTriangles(); ++t)
    inputs.grouping.groups.push_back(GroupSpec{{t}, 0.0});
  std::unique_ptr<PaintSession> session;
  ASSERT_TRUE(PaintSession::Create(inputs, &session).ok());
  ASSERT_EQ(session->buffers().size(), 12u);
  EXPECT_GE(session->atlas().pages.size(), 3u);
  FrameReport report;
  for (size_t i = 0; i < capture.frames_bgr.size(); ++i) {
    Frame frame;
    frame.index = static_cast<int>(i);
    frame.bgr = capture.frames_bgr[i];
    session->PaintFrame(frame, capture.camera, capture.true_poses[i].cam_from_world, &report);
  }
  const Scene by_buffer = session->PaintedSceneByBuffer();
  const Scene atlas = session->PaintedScene();
  EXPECT_EQ(atlas.textures.size(), session->atlas().pages.size());
  EXPECT_EQ(by_buffer.textures.size(), 12u);
  RenderOptions render_options;  // bilinear, one sample per pixel: borders show any bleeding
  const Renderer renderer(capture.camera, render_options);
  for (size_t i = 0; i < capture.true_poses.size(); i += 3) {
    RenderOutput a, b;
    renderer.Render(by_buffer, capture.true_poses[i].cam_from_world, &a);
    renderer.Render(atlas, capture.true_poses[i].cam_from_world, &b);
    std::vector<cv::Mat> ca, cb;
    cv::split(a.rgba, ca);
    cv::split(b.rgba, cb);
    // Painted where the per-buffer model is painted, texel for texel.
    const cv::Mat alpha_differs = ca[3] != cb[3];
    EXPECT_EQ(cv::countNonZero(alpha_differs), 0) << "pose " << i;
    const cv::Mat both = (ca[3] == 255) & (cb[3] == 255);
    ASSERT_GT(cv::countNonZero(both), 1000);
    cv::Mat rgb_a, rgb_b;
    cv::cvtColor(a.rgba, rgb_a, cv::COLOR_RGBA2RGB);
    cv::cvtColor(b.rgba, rgb_b, cv::COLOR_RGBA2RGB);
    EXPECT_GE(PsnrDb(rgb_a, rgb_b, both), 45.0) << "pose " << i;
    // No pixel is far off (bleeding would show as a few very wrong pixels at borders).
    cv::Mat diff;
    cv::absdiff(rgb_a, rgb_b, diff);
    std::vector<cv::Mat> channels;
    cv::split(diff, channels);
    const cv::Mat largest = cv::max(cv::max(channels[0], channels[1]), channels[2]);
    double worst = 0;
    cv::minMaxLoc(largest, nullptr, &worst, nullptr, nullptr, both);
    EXPECT_LE(worst, 8.0) << "pose " << i;
  }
}

}  // namespace
}  // namespace fresco
