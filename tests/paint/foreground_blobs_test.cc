// The background model's foreground cleaning (pipeline/paint/foreground_blobs.h) against what
// OpenCV's connected components, area test and elliptic dilation give on the same masks:
// random noise and blobs of every size, touching the borders, with and without a parent
// image around the region.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "pipeline/paint/foreground_blobs.h"

namespace fresco {
namespace {

// The reference: OpenCV's passes, as the background model ran them before.
cv::Mat Reference(const cv::Mat& raw, int min_blob, int dilate, int* dropped) {
  cv::Mat kept = raw.clone();
  *dropped = 0;
  if (min_blob > 1) {
    cv::Mat labels, stats, centroids;
    const int n = cv::connectedComponentsWithStats(raw, labels, stats, centroids, 8, CV_32S);
    std::vector<uint8_t> keep(n, 0);
    for (int i = 1; i < n; ++i) {
      keep[i] = stats.at<int>(i, cv::CC_STAT_AREA) >= min_blob ? 255 : 0;
      *dropped += keep[i] == 0;
    }
    for (int y = 0; y < raw.rows; ++y)
      for (int x = 0; x < raw.cols; ++x) kept.at<uint8_t>(y, x) = keep[labels.at<int>(y, x)];
  } else {
    kept.setTo(255, raw != 0);
  }
  if (dilate <= 0) return kept;
  cv::Mat out;
  cv::dilate(
      kept, out,
      cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * dilate + 1, 2 * dilate + 1)));
  return out;
}

// Blurred noise thresholded: blobs from single texels to a few hundred, some on the border.
cv::Mat RandomMask(int rows, int cols, double sigma, double threshold, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat noise(rows, cols, CV_32F);
  rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
  if (sigma > 0) cv::GaussianBlur(noise, noise, cv::Size(0, 0), sigma);
  return noise > threshold;
}

TEST(CleanForeground, MatchesOpenCvComponentsAndDilation) {
  int cases = 0, dropped_total = 0;
  for (uint64_t seed = 1; seed <= 6; ++seed)
    for (const auto& [sigma, threshold] :
         std::vector<std::pair<double, double>>{{0.0, 0.93}, {1.0, 0.58}, {1.5, 0.54}, {2.5, 0.52}})
      for (const int min_blob : {1, 2, 12, 40})
        for (const int dilate : {0, 1, 2, 3, 5}) {
          const cv::Mat raw =
              RandomMask(37 + 11 * static_cast<int>(seed), 61, sigma, threshold, seed);
          int expected_dropped = 0;
          const cv::Mat expected = Reference(raw, min_blob, dilate, &expected_dropped);
          cv::Mat out = cv::Mat::zeros(raw.size(), CV_8U);
          const int dropped = CleanForeground(raw, min_blob, dilate, &out);
          ASSERT_EQ(cv::norm(out, expected, cv::NORM_INF), 0)
              << "seed " << seed << " sigma " << sigma << " min_blob " << min_blob << " dilate "
              << dilate;
          ASSERT_EQ(dropped, expected_dropped);
          dropped_total += dropped;
          ++cases;
        }
  EXPECT_EQ(cases, 6 * 4 * 4 * 5);
  EXPECT_GT(dropped_total, 1000);  // the masks do have small blobs to drop
}

TEST(CleanForeground, WorksOnARegionOfALargerImage) {
  // As the model calls it: a region of the buffer's raw foreground, written into the same
  // region of the (zeroed) foreground image; nothing outside the region is touched.
  const cv::Mat whole = RandomMask(90, 120, 1.5, 0.54, 7);
  const cv::Rect roi(13, 9, 70, 60);
  cv::Mat region_copy = whole(roi).clone();
  int expected_dropped = 0;
  const cv::Mat expected = Reference(region_copy, 12, 2, &expected_dropped);
  cv::Mat foreground = cv::Mat::zeros(whole.size(), CV_8U);
  cv::Mat out = foreground(roi);
  EXPECT_EQ(CleanForeground(whole(roi), 12, 2, &out), expected_dropped);
  EXPECT_EQ(cv::norm(foreground(roi), expected, cv::NORM_INF), 0);
  cv::Mat outside = foreground.clone();
  outside(roi).setTo(0);
  EXPECT_EQ(cv::countNonZero(outside), 0);
}

TEST(CleanForeground, DiagonalNeighboursAreOneBlob) {
  cv::Mat raw = cv::Mat::zeros(8, 8, CV_8U);
  for (int i = 0; i < 6; ++i) raw.at<uint8_t>(i, i) = 255;  // one diagonal line of 6
  raw.at<uint8_t>(7, 0) = 255;                              // and a lone texel
  cv::Mat out = cv::Mat::zeros(raw.size(), CV_8U);
  EXPECT_EQ(CleanForeground(raw, 6, 0, &out), 1);  // the lone texel only
  EXPECT_EQ(cv::countNonZero(out), 6);
  EXPECT_EQ(out.at<uint8_t>(7, 0), 0);
}

TEST(CleanForeground, RejectsMismatchedImages) {
  cv::Mat raw = cv::Mat::zeros(4, 4, CV_8U), out = cv::Mat::zeros(4, 5, CV_8U);
  EXPECT_THROW(CleanForeground(raw, 2, 1, &out), std::invalid_argument);
}

}  // namespace
}  // namespace fresco
