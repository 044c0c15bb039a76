// The paint stage's update (pipeline/paint/paint_update.h) on a two-texel buffer: replace (the
// paper's) or a running average with weight PipelineOptions::update_weight.
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

}  // namespace
}  // namespace fresco
