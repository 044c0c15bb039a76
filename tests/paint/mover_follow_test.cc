// Movers followed by their colours (mover_follow.h): a plain square moving over a textured
// background, found in one frame, is followed into the frames next to it and no further than
// asked; not onto the background, not where its colours do not set it apart, and not onto
// pixels that may not join.
#include "pipeline/paint/mover_follow.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace fresco {
namespace {

constexpr int kFrames = 10;
const cv::Size kSize(96, 64);
const cv::Scalar kRed(30, 40, 220);

cv::Rect SquareAt(int frame) { return cv::Rect(10 + 3 * frame, 20, 14, 14); }

// Grey texture (60-200, seeded), with vertical stripes of the square's colour (2 pixels of
// every 5) when `stripes`, and the square at its place in each frame.
std::vector<FollowFrame> Frames(const cv::Scalar& square_colour, bool stripes) {
  std::vector<FollowFrame> frames(kFrames);
  cv::RNG rng(7);
  for (int f = 0; f < kFrames; ++f) {
    cv::Mat grey(kSize, CV_8U);
    rng.fill(grey, cv::RNG::UNIFORM, 60, 200);
    cv::cvtColor(grey, frames[f].bgr, cv::COLOR_GRAY2BGR);
    if (stripes)
      for (int x = 0; x < kSize.width; x += 5)
        frames[f]
            .bgr(cv::Rect(x, 0, 2, kSize.height) & cv::Rect(cv::Point(), kSize))
            .setTo(square_colour);
    frames[f].bgr(SquareAt(f)).setTo(square_colour);
    frames[f].joinable = cv::Mat(kSize, CV_8U, cv::Scalar(255));
  }
  return frames;
}

// Masks with the square found in frame 0 only.
std::vector<cv::Mat> FoundInFirstFrame() {
  std::vector<cv::Mat> masks(kFrames);
  for (cv::Mat& m : masks) m = cv::Mat::zeros(kSize, CV_8U);
  masks[0](SquareAt(0)).setTo(255);
  return masks;
}

double Covered(const cv::Mat& mask, const cv::Rect& square) {
  return cv::countNonZero(mask(square)) / static_cast<double>(square.area());
}

int Outside(const cv::Mat& mask, const cv::Rect& square) {
  cv::Mat rest = mask.clone();
  rest(square).setTo(0);
  return cv::countNonZero(rest);
}

TEST(MoverFollow, APlainMoverIsFollowedAsFarAsAskedAndNotOntoTheBackground) {
  const std::vector<FollowFrame> frames = Frames(kRed, false);
  std::vector<cv::Mat> masks = FoundInFirstFrame();
  FollowMovers(frames, 6, &masks);
  for (int f = 1; f <= 6; ++f) {
    EXPECT_EQ(Covered(masks[f], SquareAt(f)), 1.0) << "frame " << f;
    EXPECT_EQ(Outside(masks[f], SquareAt(f)), 0) << "frame " << f;
  }
  for (int f = 7; f < kFrames; ++f) EXPECT_EQ(cv::countNonZero(masks[f]), 0) << "frame " << f;
  EXPECT_EQ(cv::countNonZero(masks[0]), SquareAt(0).area());
}

TEST(MoverFollow, NotWhereItsColoursAreAroundIt) {
  // The square on a background striped with its colour: its colours do not tell it apart.
  const std::vector<FollowFrame> frames = Frames(kRed, true);
  std::vector<cv::Mat> masks = FoundInFirstFrame();
  FollowMovers(frames, 6, &masks);
  for (int f = 1; f < kFrames; ++f) EXPECT_EQ(cv::countNonZero(masks[f]), 0) << "frame " << f;
}

TEST(MoverFollow, OnlyOntoPixelsThatMayJoin) {
  std::vector<FollowFrame> frames = Frames(kRed, false);
  frames[1].joinable.setTo(0);
  std::vector<cv::Mat> masks = FoundInFirstFrame();
  FollowMovers(frames, 6, &masks);
  EXPECT_EQ(cv::countNonZero(masks[1]), 0);
  // Not followed past a frame it was not found in.
  for (int f = 2; f < kFrames; ++f) EXPECT_EQ(cv::countNonZero(masks[f]), 0) << "frame " << f;
}

TEST(MoverFollow, BackwardsToo) {
  const std::vector<FollowFrame> frames = Frames(kRed, false);
  std::vector<cv::Mat> masks(kFrames);
  for (cv::Mat& m : masks) m = cv::Mat::zeros(kSize, CV_8U);
  masks[kFrames - 1](SquareAt(kFrames - 1)).setTo(255);
  FollowMovers(frames, 2, &masks);
  EXPECT_EQ(Covered(masks[kFrames - 2], SquareAt(kFrames - 2)), 1.0);
  EXPECT_EQ(Covered(masks[kFrames - 3], SquareAt(kFrames - 3)), 1.0);
  EXPECT_EQ(cv::countNonZero(masks[kFrames - 4]), 0);
}

}  // namespace
}  // namespace fresco
