// The paint stage's update (pipeline/paint/paint_update.h) on a two-texel buffer: replace (the
// paper's) or a running average with weight PipelineOptions::update_weight; provisional
// samples while the background model warms up.
#include <random>

#include <gtest/gtest.h>

#include "pipeline/paint/paint_update.h"

namespace fresco {
namespace {

struct TwoTexels {
  BaseBuffer buffer;
  WarpedBuffer warped;
  PaintedBuffer painted;
  TwoTexels() {
    buffer.width = 2, buffer.height = 1;
    buffer.texel_index = {0, 1};
    buffer.on_surface = {1, 1};
    InitPaintedBuffer(buffer, &painted);
    warped.valid = cv::Mat(1, 2, CV_8U, cv::Scalar(255));
    warped.quality = cv::Mat(1, 2, CV_32F, cv::Scalar(1));
  }
  void Paint(int grey, const PipelineOptions& options) {
    warped.bgr = cv::Mat(1, 2, CV_8UC3, cv::Scalar(grey, grey, grey));
    PaintBuffer(buffer, warped, cv::Mat(), options, &painted);
  }
  int Stored() const { return painted.bgra.at<cv::Vec4b>(0, 1)[0]; }
};

TEST(PaintUpdate, WeightOneReplacesLowerWeightsAverage) {
  PipelineOptions options;
  TwoTexels replace;
  replace.Paint(100, options);
  replace.Paint(200, options);
  EXPECT_EQ(replace.Stored(), 200);
  EXPECT_EQ(replace.painted.painted_surface_texels, 2);

  options.update_weight = 0.25;
  TwoTexels average;
  average.Paint(100, options);  // the first sample is taken whole
  EXPECT_EQ(average.Stored(), 100);
  average.Paint(200, options);
  EXPECT_EQ(average.Stored(), 125);
  average.Paint(200, options);
  EXPECT_NEAR(average.Stored(), 144, 1);  // 125 + 0.25 * 75
  EXPECT_EQ(average.painted.painted_surface_texels, 2);
}

// `update: mean`: each texel the mean of every sample it took, weighted by the samples'
// quality (pixels per texel); masked samples do not count; the sums go with InitPaintedBuffer.
TEST(PaintUpdate, MeanWeighsEverySampleByItsQuality) {
  PipelineOptions options;
  options.update = UpdatePolicy::kMean;
  TwoTexels t;
  t.Paint(100, options);
  EXPECT_EQ(t.Stored(), 100);
  EXPECT_EQ(t.painted.painted_surface_texels, 2);
  t.Paint(200, options);
  EXPECT_EQ(t.Stored(), 150);
  t.warped.quality.setTo(0.5f);  // half as sharp: half the weight
  t.Paint(45, options);
  EXPECT_EQ(t.Stored(), 129);                                // (100 + 200 + 0.5 * 45) / 2.5
  EXPECT_FLOAT_EQ(t.painted.quality.at<float>(0, 1), 1.0f);  // the best seen
  const cv::Mat masked(1, 2, CV_8U, cv::Scalar(255));
  t.warped.bgr.setTo(cv::Scalar::all(0));
  PaintBuffer(t.buffer, t.warped, masked, options, &t.painted, masked);
  EXPECT_EQ(t.Stored(), 129);
  InitPaintedBuffer(t.buffer, &t.painted);
  t.Paint(10, options);
  EXPECT_EQ(t.Stored(), 10);
}

// While the background model learns a texel its samples are provisional (they may show a
// mover): in the mean they count among themselves until the texel's first trusted sample,
// which replaces them; after it, a provisional sample counts as nothing.
TEST(PaintUpdate, MeanKeepsProvisionalSamplesOnlyUntilATrustedOne) {
  PipelineOptions options;
  options.update = UpdatePolicy::kMean;
  TwoTexels t;
  const cv::Mat warming(1, 2, CV_8U, cv::Scalar(255));
  const auto paint = [&](int grey, bool provisional) {
    t.warped.bgr = cv::Mat(1, 2, CV_8UC3, cv::Scalar::all(grey));
    PaintBuffer(t.buffer, t.warped, cv::Mat(), options, &t.painted,
                provisional ? warming : cv::Mat());
  };
  paint(0, true);  // a mover passing while the model learns
  EXPECT_EQ(t.Stored(), 0);
  paint(40, true);
  EXPECT_EQ(t.Stored(), 20);  // provisional ones average among themselves
  paint(200, false);
  EXPECT_EQ(t.Stored(), 200);  // the first trusted one replaces them
  paint(100, false);
  EXPECT_EQ(t.Stored(), 150);
  paint(0, true);
  EXPECT_EQ(t.Stored(), 150);  // after it, a provisional one counts as nothing
  EXPECT_FLOAT_EQ(t.painted.mean_sum.at<cv::Vec4f>(0, 1)[3], 2.0f);
}

// `update: auto` while deciding: the texels as `quality` paints them, the sums as `mean`
// keeps them (masked samples left out of both).
TEST(PaintUpdate, AutoWhileDecidingKeepsTheSharpestAndTheMean) {
  PipelineOptions options;
  options.update = UpdatePolicy::kAuto;
  TwoTexels deciding, quality;
  PipelineOptions quality_options;
  quality_options.update = UpdatePolicy::kQuality;
  for (const auto& [grey, q] : {std::pair{100, 0.5f}, {200, 0.45f}, {0, 0.3f}, {40, 1.0f}}) {
    deciding.warped.quality.setTo(q);
    deciding.Paint(grey, options);
    quality.warped.quality.setTo(q);
    quality.Paint(grey, quality_options);
  }
  EXPECT_EQ(deciding.Stored(), 40);
  EXPECT_EQ(cv::norm(deciding.painted.bgra, quality.painted.bgra, cv::NORM_INF), 0.0);
  ASSERT_FALSE(deciding.painted.mean_sum.empty());
  const cv::Vec4f sum = deciding.painted.mean_sum.at<cv::Vec4f>(0, 1);
  EXPECT_NEAR(sum[0] / sum[3], (50 + 90 + 0 + 40) / 2.25, 1e-3);
  const cv::Mat masked(1, 2, CV_8U, cv::Scalar(255));
  PaintBuffer(deciding.buffer, deciding.warped, masked, options, &deciding.painted);
  EXPECT_FLOAT_EQ(deciding.painted.mean_sum.at<cv::Vec4f>(0, 1)[3], 2.25f);
}

// `update: sharp_mean`: the mean with each sample weighted by the pixels its view has on the
// texel (pixels per texel squared, not capped); `mean` and `quality` count pixels per texel up
// to 1. `auto` while deciding keeps the sharp sums beside the mean's.
TEST(PaintUpdate, SharpMeanWeighsSamplesByTheirPixelsOnTheTexel) {
  PipelineOptions sharp_options, mean_options, auto_options;
  sharp_options.update = UpdatePolicy::kSharpMean;
  mean_options.update = UpdatePolicy::kMean;
  auto_options.update = UpdatePolicy::kAuto;
  TwoTexels sharp, mean, deciding;
  for (const auto& [grey, q] : {std::pair{100, 3.0f}, {200, 1.0f}, {40, 0.5f}}) {
    for (TwoTexels* t : {&sharp, &mean, &deciding}) t->warped.quality.setTo(q);
    sharp.Paint(grey, sharp_options);
    mean.Paint(grey, mean_options);
    deciding.Paint(grey, auto_options);
  }
  // (9 * 100 + 200 + 0.25 * 40) / 10.25 = 108.3; the mean: (100 + 200 + 0.5 * 40) / 2.5
  EXPECT_EQ(sharp.Stored(), 108);
  EXPECT_EQ(mean.Stored(), 128);
  EXPECT_FLOAT_EQ(mean.painted.quality.at<float>(0, 1), 1.0f);  // the best seen, counted to 1
  ASSERT_FALSE(deciding.painted.sharp_sum.empty());
  const cv::Vec4f s = deciding.painted.sharp_sum.at<cv::Vec4f>(0, 1);
  EXPECT_NEAR(s[0] / s[3], (900 + 200 + 10) / 10.25, 1e-3);
  const cv::Vec4f m = deciding.painted.mean_sum.at<cv::Vec4f>(0, 1);
  EXPECT_NEAR(m[0] / m[3], 128.0, 1e-3);
}

// While a texel's background model warms up its samples are provisional (PaintBuffer's `warming`):
// a later provisional sample replaces the stored one only when it is as sharp (the quality
// rule), a trusted one whatever its quality, even one showing nearly the same (per-texel
// agreement tests left a patchwork of two photos on the real castle photos).
TEST(PaintUpdate, ProvisionalSamplesKeepTheSharperAndGiveWayToTrustedOnes) {
  PipelineOptions options;  // quality policy, slack 0.2
  TwoTexels t;
  const cv::Mat warming(1, 2, CV_8U, cv::Scalar(255));
  const auto paint_into = [&](TwoTexels* into, int grey, float quality, bool provisional) {
    into->warped.bgr = cv::Mat(1, 2, CV_8UC3, cv::Scalar(grey, grey, grey));
    into->warped.quality.setTo(quality);
    PaintBuffer(into->buffer, into->warped, cv::Mat(), options, &into->painted,
                provisional ? warming : cv::Mat());
  };
  const auto paint = [&](int grey, float quality, bool provisional) {
    paint_into(&t, grey, quality, provisional);
  };
  paint(100, 1.0f, true);  // sharp, provisional
  EXPECT_EQ(t.Stored(), 100);
  EXPECT_LT(t.painted.quality.at<float>(0, 1), 0.0f);  // marked provisional
  paint(150, 0.5f, true);                              // blurrier, provisional: the sharper stays
  EXPECT_EQ(t.Stored(), 100);
  paint(160, 0.9f, true);  // nearly as sharp (within the slack): replaces
  EXPECT_EQ(t.Stored(), 160);
  paint(200, 0.3f, false);  // trusted, however blurry: replaces
  EXPECT_EQ(t.Stored(), 200);
  EXPECT_FLOAT_EQ(t.painted.quality.at<float>(0, 1), 0.3f);
  paint(220, 0.1f, false);  // trusted against trusted: the quality rule
  EXPECT_EQ(t.Stored(), 200);

  TwoTexels near;  // a trusted sample 20 levels off, blurrier: still replaces
  paint_into(&near, 100, 1.0f, true);
  paint_into(&near, 120, 0.3f, false);
  EXPECT_EQ(near.Stored(), 120);
  EXPECT_FLOAT_EQ(near.painted.quality.at<float>(0, 1), 0.3f);
}

// The update walks each rectangle row by row when InitPaintedBuffer has laid out which texels
// are the buffer's; the texel order (tile by tile through texel_index) must give the same
// texels, qualities and figures, frame after frame, with masks, provisional samples, and
// valid flags on rectangle texels that are not the buffer's (refinement warps `valid`).
TEST(PaintUpdate, RowByRowEqualsTheTexelOrder) {
  BaseBuffer buffer;
  buffer.width = 40, buffer.height = 24;
  std::mt19937 rng(3);
  const auto coin = [&](int percent) { return static_cast<int>(rng() % 100) < percent; };
  cv::Mat member(buffer.height, buffer.width, CV_8U);
  for (int y = 0; y < buffer.height; ++y)
    for (int x = 0; x < buffer.width; ++x) member.at<uint8_t>(y, x) = x + y > 6 && x < 37;
  for (int ty = 0; ty < buffer.height; ty += 16) {
    for (int tx = 0; tx < buffer.width; tx += 16) {
      BaseBuffer::Chunk chunk;
      chunk.x0 = tx, chunk.y0 = ty;
      chunk.x1 = std::min(tx + 16, buffer.width), chunk.y1 = std::min(ty + 16, buffer.height);
      chunk.begin = buffer.NumTexels();
      for (int y = chunk.y0; y < chunk.y1; ++y)
        for (int x = chunk.x0; x < chunk.x1; ++x)
          if (member.at<uint8_t>(y, x)) {
            buffer.texel_index.push_back(y * buffer.width + x);
            buffer.on_surface.push_back(coin(80));
          }
      chunk.end = buffer.NumTexels();
      buffer.chunks.push_back(chunk);
    }
  }
  PaintedBuffer rows, texels;
  InitPaintedBuffer(buffer, &rows);
  InitPaintedBuffer(buffer, &texels);
  ASSERT_EQ(cv::countNonZero(rows.texel_kind), buffer.NumTexels());
  texels.texel_kind.release();  // the texel order
  PipelineOptions options;
  for (int frame = 0; frame < 18; ++frame) {
    if (frame == 12) {  // then the mean, onto what the quality rule painted
      options.update = UpdatePolicy::kMean;
      rows.quality.setTo(0, rows.quality < 0);
      texels.quality.setTo(0, texels.quality < 0);
    }
    WarpedBuffer warped;
    warped.bgr.create(buffer.height, buffer.width, CV_8UC3);
    cv::randu(warped.bgr, cv::Scalar::all(0), cv::Scalar::all(256));
    warped.valid = cv::Mat::zeros(buffer.height, buffer.width, CV_8U);
    warped.quality.create(buffer.height, buffer.width, CV_32F);
    cv::randu(warped.quality, 0.1, 1.0);
    cv::Mat mask = cv::Mat::zeros(buffer.height, buffer.width, CV_8U);
    cv::Mat warming = cv::Mat::zeros(buffer.height, buffer.width, CV_8U);
    // A window of the rectangle in view; inside it most texels valid, including texels that
    // are not the buffer's.
    const cv::Rect view(static_cast<int>(rng() % 12), static_cast<int>(rng() % 8),
                        20 + static_cast<int>(rng() % 9), 12 + static_cast<int>(rng() % 5));
    for (int y = view.y; y < view.br().y; ++y)
      for (int x = view.x; x < view.br().x; ++x) {
        warped.valid.at<uint8_t>(y, x) = coin(85) ? 255 : 0;
        mask.at<uint8_t>(y, x) = coin(10) ? 255 : 0;
        warming.at<uint8_t>(y, x) = frame < 6 && coin(50) ? 255 : 0;
      }
    warped.valid_box = view;
    const PaintUpdateStats a = PaintBuffer(buffer, warped, mask, options, &rows, warming);
    const PaintUpdateStats b = PaintBuffer(buffer, warped, mask, options, &texels, warming);
    EXPECT_EQ(a.written, b.written) << frame;
    EXPECT_EQ(a.rejected, b.rejected) << frame;
    EXPECT_EQ(a.compared, b.compared) << frame;
    EXPECT_EQ(a.abs_grey_difference_sum, b.abs_grey_difference_sum) << frame;
    EXPECT_EQ(a.newly_painted, b.newly_painted) << frame;
    EXPECT_GT(a.written, 50) << frame;
    ASSERT_EQ(cv::norm(rows.bgra, texels.bgra, cv::NORM_INF), 0.0) << frame;
    ASSERT_EQ(cv::norm(rows.quality, texels.quality, cv::NORM_INF), 0.0) << frame;
  }
  EXPECT_EQ(rows.painted_surface_texels, texels.painted_surface_texels);
  // Rectangle texels that are not the buffer's were never painted, valid or not.
  cv::Mat alpha;
  cv::extractChannel(rows.bgra, alpha, 3);
  EXPECT_EQ(cv::countNonZero(alpha & (member == 0)), 0);
}

}  // namespace
}  // namespace fresco
