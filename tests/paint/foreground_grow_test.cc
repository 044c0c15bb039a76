// Foreground grown by colour (pipeline/paint/foreground_grow.h): a yellow disc on a textured
// wall, flagged only at its leading edge, is flagged whole; the wall (other colours), texels
// not sampled and texels beyond the reach stay unflagged; a gradient does not carry the flag
// away from its seed's colour.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "pipeline/paint/foreground_grow.h"

namespace fresco {
namespace {

struct Scene {
  cv::Mat bgr = cv::Mat(64, 96, CV_8UC3);
  cv::Mat valid = cv::Mat(64, 96, CV_8U, cv::Scalar(255));
  cv::Mat disc = cv::Mat::zeros(64, 96, CV_8U);
  Scene() {
    cv::randu(bgr, cv::Scalar(60, 60, 60), cv::Scalar(140, 140, 140));  // a grey, noisy wall
    cv::circle(disc, cv::Point(40, 32), 14, cv::Scalar(255), cv::FILLED);
    bgr.setTo(cv::Scalar(0, 220, 255), disc);  // a yellow mover
  }
};

TEST(ForegroundGrow, AFlaggedEdgeFlagsTheWholeMoverAndNothingElse) {
  Scene s;
  cv::Mat flagged = cv::Mat::zeros(s.disc.size(), CV_8U);
  flagged(cv::Rect(50, 26, 5, 12)).setTo(255);  // the leading edge only
  flagged &= s.disc;
  ASSERT_GT(cv::countNonZero(flagged), 20);
  const int added = GrowForegroundByColour(s.bgr, s.valid, 32, 256, &flagged);
  EXPECT_EQ(cv::countNonZero(flagged), cv::countNonZero(s.disc));
  EXPECT_EQ(cv::countNonZero(flagged & ~s.disc), 0);
  EXPECT_GT(added, 400);
}

TEST(ForegroundGrow, StopsAtUnsampledTexelsAndAtItsReach) {
  Scene s;
  s.valid(cv::Rect(0, 0, 40, 64)).setTo(0);  // the disc's left half not sampled this frame
  cv::Mat flagged = cv::Mat::zeros(s.disc.size(), CV_8U);
  flagged.at<uint8_t>(32, 53) = 255;
  GrowForegroundByColour(s.bgr, s.valid, 32, 256, &flagged);
  EXPECT_EQ(cv::countNonZero(flagged(cv::Rect(0, 0, 40, 64))), 0);
  EXPECT_EQ(cv::countNonZero(flagged), cv::countNonZero(s.disc(cv::Rect(40, 0, 56, 64))));

  cv::Mat near = cv::Mat::zeros(s.disc.size(), CV_8U);
  near.at<uint8_t>(32, 40) = 255;  // the disc's centre
  GrowForegroundByColour(s.bgr, Scene().valid, 32, 3, &near);  // 3 steps: a diamond
  EXPECT_EQ(cv::countNonZero(near), 25);
}

TEST(ForegroundGrow, AGradientDoesNotCarryTheFlagAway) {
  cv::Mat ramp(1, 200, CV_8UC3);
  for (int x = 0; x < 200; ++x) ramp.at<cv::Vec3b>(0, x) = cv::Vec3b(x, x, x);
  const cv::Mat valid(1, 200, CV_8U, cv::Scalar(255));
  cv::Mat flagged = cv::Mat::zeros(1, 200, CV_8U);
  flagged.at<uint8_t>(0, 0) = 255;
  GrowForegroundByColour(ramp, valid, 32, 1000, &flagged);
  EXPECT_EQ(cv::countNonZero(flagged), 33);  // grey 0..32: within 32 of the seed's 0
  EXPECT_EQ(GrowForegroundByColour(ramp, valid, 0, 1000, &flagged), 0);  // off
}

}  // namespace
}  // namespace fresco
