// Regions of one colour ringed by a mask (ringed_regions.h): a plain square on a textured
// background whose edges are masked joins the mask whole, shading and all; one masked along too
// little of its boundary does not, nor does the textured background beside it; the image's
// border and the pixels off the surface do not count as boundary; a frame's regions kept
// between masks give what fresh ones give.
#include "pipeline/paint/ringed_regions.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace fresco {
namespace {

const cv::Size kSize(96, 64);
const cv::Rect kSquare(30, 12, 36, 40);

// Grey texture (60-200, seeded) and a red square shaded from top to bottom (1 level a row).
cv::Mat Frame() {
  cv::Mat grey(kSize, CV_8U), bgr;
  cv::RNG rng(5);
  rng.fill(grey, cv::RNG::UNIFORM, 60, 200);
  cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
  for (int y = kSquare.y; y < kSquare.br().y; ++y)
    bgr(cv::Rect(kSquare.x, y, kSquare.width, 1)).setTo(cv::Scalar(30, 40, 200 + y - kSquare.y));
  return bgr;
}

cv::Mat AllSurface() { return cv::Mat(kSize, CV_8U, cv::Scalar(255)); }

// The mask a comparison across views gives a plain mover: its edges, `sides` of them (top,
// right, bottom, left), two pixels wide on either side of the edge.
cv::Mat EdgeMask(int sides) {
  cv::Mat mask = cv::Mat::zeros(kSize, CV_8U);
  const cv::Rect s = kSquare;
  const cv::Rect edges[4] = {
      cv::Rect(s.x - 2, s.y - 2, s.width + 4, 4), cv::Rect(s.br().x - 2, s.y - 2, 4, s.height + 4),
      cv::Rect(s.x - 2, s.br().y - 2, s.width + 4, 4), cv::Rect(s.x - 2, s.y - 2, 4, s.height + 4)};
  for (int i = 0; i < sides; ++i) mask(edges[i]).setTo(255);
  return mask;
}

double Covered(const cv::Mat& ringed) {
  return cv::countNonZero(ringed(kSquare)) / static_cast<double>(kSquare.area());
}

int Outside(const cv::Mat& ringed) {
  cv::Mat rest = ringed.clone();
  rest(kSquare).setTo(0);
  return cv::countNonZero(rest);
}

TEST(RingedRegions, APlainMoverRingedByTheMaskJoinsItWholeAndTheBackgroundDoesNot) {
  const cv::Mat frame = Frame();
  int count = 0;
  const cv::Mat labels = ColourRegions(frame, RingedRegionOptions().levels, &count);
  // The shaded square is one region; the texture is hundreds of small ones.
  EXPECT_EQ(cv::countNonZero(labels(kSquare) == labels.at<int>(kSquare.y, kSquare.x)),
            kSquare.area());
  EXPECT_GT(count, 500);
  for (int sides : {3, 4}) {
    const cv::Mat ringed = RingedRegions(frame, EdgeMask(sides), AllSurface(), {});
    EXPECT_EQ(Covered(ringed), 1.0) << sides << " sides masked";
    EXPECT_EQ(Outside(ringed), 0) << sides << " sides masked";
  }
  // One side of four (a quarter of its boundary) is not enough.
  EXPECT_EQ(cv::countNonZero(RingedRegions(frame, EdgeMask(1), AllSurface(), {})), 0);
  // Nor is any mask with the share 0 (off), nor a region larger than max_share of the frame.
  RingedRegionOptions off;
  off.share = 0;
  EXPECT_EQ(cv::countNonZero(RingedRegions(frame, EdgeMask(4), AllSurface(), off)), 0);
  RingedRegionOptions small;
  small.max_share = 0.5 * kSquare.area() / kSize.area();
  EXPECT_EQ(cv::countNonZero(RingedRegions(frame, EdgeMask(4), AllSurface(), small)), 0);
}

TEST(RingedRegions, TheImageBorderAndPixelsOffTheSurfaceAreNotBoundary) {
  // The square at the image's left border (its 36 x 40 pixels), masked along its right side
  // only: with the corners the mask reaches, about 48 of its 110 boundary pixels with the
  // surface below it, short of a half (the border is not boundary; counted, 48 of 150) ...
  const cv::Mat frame = Frame();
  cv::Mat cut_frame = Frame();
  const int shift = kSquare.x;
  frame(cv::Rect(shift, 0, kSize.width - shift, kSize.height))
      .copyTo(cut_frame(cv::Rect(0, 0, kSize.width - shift, kSize.height)));
  const cv::Rect cut(0, kSquare.y, kSquare.br().x - shift, kSquare.height);
  cv::Mat right = cv::Mat::zeros(kSize, CV_8U);
  right(cv::Rect(cut.br().x - 2, cut.y - 2, 4, cut.height + 4)).setTo(255);
  EXPECT_EQ(cv::countNonZero(RingedRegions(cut_frame, right, AllSurface(), {})), 0);
  // ... and about 44 of 75 where the pixels below it are off the surface (the sky): it joins.
  cv::Mat sky = AllSurface();
  sky(cv::Rect(0, cut.br().y, kSize.width, kSize.height - cut.br().y)).setTo(0);
  const cv::Mat ringed = RingedRegions(cut_frame, right, sky, {});
  EXPECT_EQ(cv::countNonZero(ringed(cut)), cut.area());
  // Away from the border, the same square masked along one side does not join, sky or not.
  EXPECT_EQ(cv::countNonZero(RingedRegions(frame, EdgeMask(1), sky, {})), 0);
}

TEST(RingedRegions, RegionsKeptFromAnEarlierMaskGiveWhatFreshOnesGive) {
  // One frame judged with masks of 1, 3 and 4 sides in turn, its colour regions made by the
  // first call and kept: each result as with regions made afresh (3 and 4 sides join the
  // square, 1 does not), with the sky cutting the boundary.
  const cv::Mat frame = Frame();
  cv::Mat sky = AllSurface();
  sky(cv::Rect(0, kSquare.br().y + 3, kSize.width, kSize.height - kSquare.br().y - 3)).setTo(0);
  ColourRegionLabels kept;
  for (int sides : {1, 3, 4}) {
    const cv::Mat fresh = RingedRegions(frame, EdgeMask(sides), sky, {});
    const cv::Mat again = RingedRegions(frame, EdgeMask(sides), sky, {}, &kept);
    EXPECT_FALSE(kept.labels.empty());
    EXPECT_EQ(cv::norm(fresh, again, cv::NORM_INF), 0) << sides << " sides masked";
    EXPECT_EQ(Covered(again), sides == 1 ? 0.0 : 1.0) << sides << " sides masked";
  }
}

}  // namespace
}  // namespace fresco
