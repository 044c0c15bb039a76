// Consensus anchoring's samples and moves (pipeline/paint/refine_anchor.h) on a buffer of
// 128x96 texels (4x3 tiles of 32), against what the move must do: move only the tiles the
// frame sees, keep the paint's extent and each texel's quality, and never blend the colour of
// unpainted texels into painted ones.
#include <algorithm>
#include <cstdlib>

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "pipeline/core/project.h"
#include "pipeline/paint/refine_anchor.h"

namespace fresco {
namespace {

constexpr int kWidth = 128, kHeight = 96;

RefineAnchor EmptyAnchor() {
  const cv::Size tiles(kWidth / kAnchorTileTexels, kHeight / kAnchorTileTexels);
  RefineAnchor anchor;
  anchor.sum = cv::Mat::zeros(tiles, CV_64FC2);
  anchor.count = cv::Mat::zeros(tiles, CV_64F);
  anchor.background_pending = cv::Mat::zeros(tiles, CV_64FC2);
  anchor.surface = cv::Mat(kHeight, kWidth, CV_8U, cv::Scalar(255));
  return anchor;
}

TEST(RefineAnchor, OnlyTilesInViewMove) {
  RefineAnchor anchor = EmptyAnchor();
  RefineOptions options;             // 3 frames must agree on more than 0.1 texel
  options.anchor_window_frames = 0;  // samples do not fade: the sums are exact
  const cv::Matx33d shift(1, 0, 1.5, 0, 1, 0, 0, 0, 1);  // every frame asks for 1.5 texels in x
  const cv::Mat measured(anchor.count.size(), CV_8U, cv::Scalar(1));  // a pose: holds everywhere
  cv::Mat in_view = cv::Mat::zeros(anchor.count.size(), CV_8U);
  in_view.colRange(0, 2).setTo(1);  // the frame sees the left half
  AnchorMove move;
  EXPECT_FALSE(AddAnchorSample(shift, measured, in_view, options, &anchor, &move));
  EXPECT_FALSE(AddAnchorSample(shift, measured, in_view, options, &anchor, &move));
  ASSERT_TRUE(AddAnchorSample(shift, measured, in_view, options, &anchor, &move));
  // The tiles in view move by what the frames asked; the field fades to nothing within one
  // tile of them, and the right-most tiles (out of view, samples or not) do not move.
  const cv::Vec2f centre = move.field.at<cv::Vec2f>(48 - move.roi.y, 16 - move.roi.x);
  EXPECT_NEAR(centre[0], 1.5, 1e-3);
  EXPECT_NEAR(centre[1], 0.0, 1e-3);
  EXPECT_LE(move.roi.br().x, 3 * kAnchorTileTexels);
  // The samples out of view stay as they were: the next move there still has them.
  EXPECT_NEAR(anchor.sum.at<cv::Vec2d>(1, 3)[0], 4.5, 1e-9);
  EXPECT_NEAR(anchor.sum.at<cv::Vec2d>(1, 0)[0], 0.0, 1e-9);
}

TEST(RefineAnchor, AMoveKeepsThePaintsExtentAndQualityWithoutBleedingTheUnpainted) {
  const RefineAnchor anchor = EmptyAnchor();
  PaintedBuffer painted;
  painted.bgra = cv::Mat(kHeight, kWidth, CV_8UC4, cv::Scalar(255, 255, 255, 0));
  painted.quality = cv::Mat::zeros(kHeight, kWidth, CV_32F);
  const cv::Rect left(0, 0, kWidth / 2, kHeight);  // painted; the right half never was
  painted.bgra(left).setTo(cv::Scalar(40, 80, 120, 255));
  painted.quality(left).setTo(0.7);
  painted.painted_surface_texels = left.area();

  AnchorMove move;
  move.roi = cv::Rect(0, 0, kWidth, kHeight);
  move.field = cv::Mat(kHeight, kWidth, CV_32FC2, cv::Scalar(0.4, 0.3));  // a fraction of a texel
  MovePaintedBuffer(move, anchor, &painted);

  cv::Mat alpha;
  cv::extractChannel(painted.bgra, alpha, 3);
  EXPECT_EQ(cv::countNonZero(alpha), left.area());  // eroding it lost a column at every move
  EXPECT_EQ(painted.painted_surface_texels, left.area());
  // Every painted texel keeps its colour (the unpainted white does not bleed into the edge)
  // and its sample's quality (0 let any later frame replace it, however blurred).
  int worst = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const cv::Vec4b& texel = painted.bgra.at<cv::Vec4b>(y, x);
      if (texel[3] == 0) continue;
      worst = std::max(
          {worst, std::abs(texel[0] - 40), std::abs(texel[1] - 80), std::abs(texel[2] - 120)});
    }
  EXPECT_LE(worst, 1);
  double lowest_quality = 0;
  cv::minMaxLoc(painted.quality, &lowest_quality, nullptr, nullptr, nullptr, alpha);
  EXPECT_FLOAT_EQ(lowest_quality, 0.7f);
}

}  // namespace
}  // namespace fresco
