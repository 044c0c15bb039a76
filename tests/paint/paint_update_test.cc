// The paint stage's update (pipeline/paint/paint_update.h) on a two-texel buffer: replace (the
// paper's) or a running average with weight PipelineOptions::update_weight; provisional
// samples while the background model warms up.
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

}  // namespace
}  // namespace fresco
