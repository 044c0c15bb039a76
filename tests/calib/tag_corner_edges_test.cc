// A tag corner where no black square is (calib/tag_corner_edges.h), on one synthetic tag36h11
// tag: OpenCV's marker (1-bit border) warped by a homography onto a white gap at 8 x 8
// samples a pixel (box-filtered: each pixel the mean grey over its area), then optionally
// blurred, with grey noise. The corners are known exactly; the detector's earlier refinement
// (cv::cornerSubPix, which looks for a saddle) pulls these convex corners into the tag; the
// meeting point of the tag's edges does not.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/aruco.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/tag_corner_edges.h"

namespace fresco::calib {
namespace {

constexpr int kImagePx = 192, kSamples = 8, kMarkerPx = 80;
constexpr int kBlack = 25, kWhite = 235;

struct Tag {
  cv::Mat gray;                           // CV_8U
  std::array<Eigen::Vector2d, 4> corner;  // the true corners, in order around the tag
};

// A tag of about `edge_px` turned by `turn_rad`, its corners moved up to 8 % of the edge
// (perspective), blurred by `blur_sigma_px` (0: sharp), grey noise sigma 2. `bend` > 0 bends
// the tag's edges as a barrel lens does near the imager's corner: each point moved towards a
// centre kBendCentrePx away up and to the left by bend * (its distance from there)^3 / 1e6
// (bend 1: a 96 px edge bows about 0.5 px). `width` < 1 narrows the tag across (a board seen
// at a slant): its width is `width` times its height before the turn. `border_bits`: the tag's
// black border, 1 (OpenCV's) or 2 (Kalibr's).
constexpr double kBendCentrePx = 250;
Tag Render(double edge_px, double turn_rad, double blur_sigma_px, unsigned seed, double bend = 0,
           double width = 1, int border_bits = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.08 * edge_px, 0.08 * edge_px);
  Tag tag;
  const Eigen::Vector2d centre(0.5 * kImagePx + 0.37, 0.5 * kImagePx - 0.21);
  const double c = std::cos(turn_rad), s = std::sin(turn_rad);
  const double unit[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  std::vector<cv::Point2f> from, to;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector2d u(0.5 * width * edge_px * unit[k][0], 0.5 * edge_px * unit[k][1]);
    tag.corner[k] = centre + Eigen::Vector2d(c * u.x() - s * u.y(), s * u.x() + c * u.y()) +
                    Eigen::Vector2d(jitter(rng), jitter(rng));
    // The marker's outer corners (pixel centres at integers) and where they land in the
    // oversampled image (pixel x there covers x_fine = kSamples x + (kSamples - 1) / 2).
    from.emplace_back(static_cast<float>((unit[k][0] + 1) / 2 * kMarkerPx - 0.5),
                      static_cast<float>((unit[k][1] + 1) / 2 * kMarkerPx - 0.5));
    to.emplace_back(static_cast<float>(kSamples * tag.corner[k].x() + 0.5 * (kSamples - 1)),
                    static_cast<float>(kSamples * tag.corner[k].y() + 0.5 * (kSamples - 1)));
  }
  cv::Mat marker, fine;
  cv::aruco::drawMarker(cv::aruco::getPredefinedDictionary(cv::aruco::DICT_APRILTAG_36h11), 7,
                        kMarkerPx, marker, border_bits);
  marker.convertTo(marker, CV_32F, (kWhite - kBlack) / 255.0, kBlack);
  cv::warpPerspective(marker, fine, cv::getPerspectiveTransform(from, to),
                      cv::Size(kSamples * kImagePx, kSamples * kImagePx), cv::INTER_LINEAR,
                      cv::BORDER_CONSTANT, cv::Scalar(kWhite));
  if (bend > 0) {
    // The image point q shows the flat point Flat(q) = q + bend (q - c) |q - c|^2 / 1e6 (c the
    // centre; a barrel lens pulls points towards it): remap samples the flat image there, and
    // each true corner is the q that Flat takes to the flat corner (fixed point iteration).
    const Eigen::Vector2d c = centre - Eigen::Vector2d(kBendCentrePx, kBendCentrePx);
    const auto flat = [&](const Eigen::Vector2d& q) {
      return q + bend * (q - c) * (q - c).squaredNorm() / 1e6;
    };
    cv::Mat_<cv::Vec2f> map(fine.size());
    for (int j = 0; j < fine.rows; ++j)
      for (int i = 0; i < fine.cols; ++i) {
        const Eigen::Vector2d q((i - 0.5 * (kSamples - 1)) / kSamples,
                                (j - 0.5 * (kSamples - 1)) / kSamples);
        const Eigen::Vector2d f = flat(q);
        map(j, i) = cv::Vec2f(static_cast<float>(kSamples * f.x() + 0.5 * (kSamples - 1)),
                              static_cast<float>(kSamples * f.y() + 0.5 * (kSamples - 1)));
      }
    cv::Mat bent;
    cv::remap(fine, bent, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
              cv::Scalar(kWhite));
    fine = bent;
    for (Eigen::Vector2d& corner : tag.corner) {
      const Eigen::Vector2d target = corner;
      for (int i = 0; i < 100; ++i) corner += target - flat(corner);
    }
  }
  cv::Mat image;
  cv::resize(fine, image, cv::Size(kImagePx, kImagePx), 0, 0, cv::INTER_AREA);
  if (blur_sigma_px > 0) cv::GaussianBlur(image, image, cv::Size(0, 0), blur_sigma_px);
  cv::Mat noise(image.size(), CV_32F);
  cv::RNG(seed).fill(noise, cv::RNG::NORMAL, 0, 2);
  image += noise;
  image.convertTo(tag.gray, CV_8U);
  return tag;
}

// The detector's refinement before the edges (calib/detect.cc): cornerSubPix, its half window
// an eighth of the tag's shortest edge, from the true corners moved 0.6 px.
std::array<Eigen::Vector2d, 4> CornerSubPix(const Tag& tag) {
  double shortest = 1e9;
  for (int k = 0; k < 4; ++k)
    shortest = std::min(shortest, (tag.corner[(k + 1) % 4] - tag.corner[k]).norm());
  const int half = std::clamp(static_cast<int>(shortest / 8), 2, 6);
  std::vector<cv::Point2f> p;
  for (int k = 0; k < 4; ++k)
    p.emplace_back(static_cast<float>(tag.corner[k].x() + 0.6 * std::cos(k + 0.3)),
                   static_cast<float>(tag.corner[k].y() + 0.6 * std::sin(k + 0.3)));
  cv::cornerSubPix(tag.gray, p, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 40, 1e-3));
  std::array<Eigen::Vector2d, 4> out;
  for (int k = 0; k < 4; ++k) out[k] = Eigen::Vector2d(p[k].x, p[k].y);
  return out;
}

struct Errors {
  double saddle_rms_px = 0, edges_rms_px = 0;  // from the truth
  double saddle_out_px = 0, edges_out_px = 0;  // mean, out of the tag (negative: into it)
  int corners = 0, from_edges = 0, crossing_squares = 0;
};

// Over tags of `sizes_px` at several turns: cornerSubPix's corners, and the edges' meeting
// point started from them (as the detector does). `width`, `border_bits`: Render's.
Errors Measure(double blur_sigma_px, const std::vector<double>& sizes_px = {40, 64, 96},
               double bend = 0, double width = 1, int border_bits = 1) {
  Errors e;
  unsigned seed = 1;
  for (double edge_px : sizes_px)
    for (double turn_rad : {0.05, 0.4, 0.9, 1.3}) {
      const Tag tag = Render(edge_px, turn_rad, blur_sigma_px, seed++, bend, width, border_bits);
      const std::array<Eigen::Vector2d, 4> saddle = CornerSubPix(tag);
      const Eigen::Vector2d centre =
          0.25 * (tag.corner[0] + tag.corner[1] + tag.corner[2] + tag.corner[3]);
      for (int k = 0; k < 4; ++k) {
        const Eigen::Vector2d out = (tag.corner[k] - centre).normalized();
        Eigen::Vector2d corner;
        e.crossing_squares += CrossingSquareAt(tag.gray, saddle, k);
        if (!CornerFromEdges(tag.gray, saddle, k, &corner, nullptr, nullptr, 0.5, border_bits))
          continue;
        ++e.corners, ++e.from_edges;
        e.saddle_rms_px += (saddle[k] - tag.corner[k]).squaredNorm();
        e.edges_rms_px += (corner - tag.corner[k]).squaredNorm();
        e.saddle_out_px += (saddle[k] - tag.corner[k]).dot(out);
        e.edges_out_px += (corner - tag.corner[k]).dot(out);
      }
    }
  const int n = std::max(1, e.corners);
  e.saddle_rms_px = std::sqrt(e.saddle_rms_px / n), e.edges_rms_px = std::sqrt(e.edges_rms_px / n);
  e.saddle_out_px /= n, e.edges_out_px /= n;
  std::printf(
      "bend %.1f, width %.2f, blur %.1f px, tags %.0f-%.0f px: %d corners, cornerSubPix %.3f px "
      "rms (out %.3f), edges %.3f px rms (out %.3f)\n",
      bend, width, blur_sigma_px, sizes_px.front(), sizes_px.back(), e.corners, e.saddle_rms_px,
      e.saddle_out_px, e.edges_rms_px, e.edges_out_px);
  return e;
}

// Sharp: cornerSubPix is 0.1-0.2 px off, into the tag; the edges' meeting point well under
// (0.049 px rms with each cut's crossing, 0.014 px with the grey's area about it).
TEST(TagCornerEdgesTest, SharpCornerWhereTheEdgesMeet) {
  const Errors e = Measure(0);
  EXPECT_EQ(e.crossing_squares, 0);  // no black square at any corner
  EXPECT_EQ(e.corners, 48);          // every corner's edges found
  EXPECT_GT(e.saddle_rms_px, 0.1);   // the old refinement
  EXPECT_LT(e.edges_rms_px, 0.03);
  EXPECT_LT(std::abs(e.edges_out_px), 0.04);
}

// Blurred 1 px: cornerSubPix rounds the corner off, 0.25-0.35 px into the tag; the edges'
// meeting point stays within 0.15 px.
TEST(TagCornerEdgesTest, BlurredCornerWhereTheEdgesMeet) {
  const Errors e = Measure(1);
  EXPECT_EQ(e.crossing_squares, 0);
  EXPECT_EQ(e.corners, 48);
  EXPECT_GT(e.saddle_rms_px, 0.2);
  EXPECT_LT(e.saddle_out_px, -0.15);
  EXPECT_LT(e.edges_rms_px, 0.15);
  EXPECT_LT(std::abs(e.edges_out_px), 0.05);
}

// Small tags blurred 1 px: a cut across the edge a few pixels long does not reach the
// border's black (nor, a 1-bit border of 3-4 px, past the tag's bits behind it), so halfway
// between its own ends put the edge 0.13 px into a 24-32 px tag on average (0.17 px rms);
// halfway between the edge's dark and light levels: 0.06 px rms, 0.01 px out (0.074 px rms,
// 0.033 px out with the grey's area about the crossing: the thin border's black is never
// reached, so its window keeps a little of the light).
TEST(TagCornerEdgesTest, SmallBlurredTagCornerNotPulledIn) {
  const Errors e = Measure(1, {24, 32});
  EXPECT_EQ(e.crossing_squares, 0);
  EXPECT_EQ(e.corners, 32);
  EXPECT_LT(e.edges_rms_px, 0.1);
  EXPECT_LT(std::abs(e.edges_out_px), 0.05);
}

// A tag seen at a slant (Kalibr's 2-bit border), 32-34 px tall and half as wide, blurred 1 px: the
// edges' levels are read from the cuts near the corner, kFirst..kLast of the edge and 1.5 px past
// the cut's reach from it, and on an edge under 17.5 px fewer than five cuts were there: no edge,
// and the detector kept cornerSubPix's saddle, 0.3-0.8 px into the tag (calib_detect_elsewhere
// --border-bits 2 --margin 0.1 --gamma 0.5 --contrast 0.6 --vignette 0.5 --seeds 3 --only
// light_blur: view 6's right-hand tags, 14.7-17.8 px wide; the lens 0.103 px RMS from the
// truth where the boards were seen). Now the levels are read from five cuts at least where the
// border along the edge is 2.5 px thick or more: 4 -> 32 corners, 0.058 px rms (cornerSubPix
// 0.365 px, 0.328 px into the tag). With OpenCV's 1-bit border (under 2.5 px on these tags)
// such corners lay 0.13 px out of the tag (0.23 px rms) and are not placed so.
TEST(TagCornerEdgesTest, NarrowTagsCornersFromTheirEdges) {
  const Errors e = Measure(1, {32, 34}, 0, 0.5, 2);
  EXPECT_EQ(e.corners, 32);  // before: 4
  EXPECT_LT(e.saddle_out_px, -0.1);
  EXPECT_LT(e.edges_rms_px, 0.15);
  EXPECT_LT(std::abs(e.edges_out_px), 0.05);
}

// Edges bent by the lens: a barrel lens bows a tag's edges near the imager's corners (k1
// -0.28: 0.2-0.3 px over a 50 px edge). A straight line fitted to the edge near the corner and
// taken on to it missed the corner by about a tenth of the bow, the misses following the
// distortion (calib_detect_elsewhere, seed 3, 40 views: the corners' errors went with those
// the bend predicts, slope 1.35; the true corners moved so solved a lens 0.06 px RMS off
// where the boards were). Each edge is now a quadratic over its whole length. Here the edges
// of 64-96 px tags bow 0.3-0.5 px: with the line the corners were 0.075 px rms from the
// truth sharp, 0.064 px blurred 1 px; now 0.035 / 0.023 px.
TEST(TagCornerEdgesTest, CornerWhereBentEdgesMeet) {
  for (double blur : {0.0, 1.0}) {
    const Errors e = Measure(blur, {64, 96}, 1.0);
    EXPECT_EQ(e.corners, 32);
    EXPECT_LT(e.edges_rms_px, 0.06);
    EXPECT_LT(std::abs(e.edges_out_px), 0.02);
  }
}

// A sharp edge between pixels: where a crossing of the grey is interpolated bilinearly between
// pixels, a sharp edge (its ramp about a pixel wide) is pulled towards the pixels' centres by
// up to 0.13 px with its phase against the pixel grid, and along an edge near a pixel row or
// column the phase, and so the pull, is the same over the whole edge (0.076 px rms over ten
// phases, 0.131 px at the worst). The edge is now placed by the grey's area about the
// crossing: 0.035 px rms, 0.052 px at the worst, what 8 x 8 samples a pixel leave of the phase
// (steps of 1/8 px).
TEST(TagCornerEdgesTest, SharpEdgeIsNotPulledToThePixelsCentres) {
  constexpr int kPx = 100;
  double sum_sq = 0, worst = 0;
  int corners = 0;
  for (int step = 0; step < 10; ++step) {
    const double x0 = 30 + 0.1 * step, x1 = 70.3 + 0.1 * step, y0 = 30.2, y1 = 70.7;
    cv::Mat fine(kPx * kSamples, kPx * kSamples, CV_32F, cv::Scalar(kWhite));
    for (int j = 0; j < fine.rows; ++j)
      for (int i = 0; i < fine.cols; ++i) {
        const double x = (i + 0.5) / kSamples - 0.5, y = (j + 0.5) / kSamples - 0.5;
        if (x > x0 && x < x1 && y > y0 && y < y1) fine.at<float>(j, i) = kBlack;
      }
    cv::Mat image, gray;
    cv::resize(fine, image, cv::Size(kPx, kPx), 0, 0, cv::INTER_AREA);
    image.convertTo(gray, CV_8U);
    const std::array<Eigen::Vector2d, 4> p = {Eigen::Vector2d(x0, y0), Eigen::Vector2d(x1, y0),
                                              Eigen::Vector2d(x1, y1), Eigen::Vector2d(x0, y1)};
    Eigen::Vector2d corner;
    if (!CornerFromEdges(gray, p, 0, &corner)) continue;
    ++corners;
    sum_sq += (corner.x() - x0) * (corner.x() - x0);  // from the edge x = x0 alone
    worst = std::max(worst, std::abs(corner.x() - x0));
  }
  const double rms = std::sqrt(sum_sq / std::max(1, corners));
  std::printf("sharp edge at 10 phases: %.3f px rms, worst %.3f px\n", rms, worst);
  EXPECT_EQ(corners, 10);
  EXPECT_LT(rms, 0.045);
  EXPECT_LT(worst, 0.07);
}

// A tag whose edge shows no contrast (a flat image) gives no corner and leaves it untouched.
TEST(TagCornerEdgesTest, NoEdgeNoCorner) {
  const cv::Mat flat(kImagePx, kImagePx, CV_8U, cv::Scalar(128));
  const std::array<Eigen::Vector2d, 4> p = {Eigen::Vector2d(50, 50), Eigen::Vector2d(110, 50),
                                            Eigen::Vector2d(110, 110), Eigen::Vector2d(50, 110)};
  Eigen::Vector2d corner(-7, -7);
  EXPECT_FALSE(CornerFromEdges(flat, p, 0, &corner));
  EXPECT_EQ(corner, Eigen::Vector2d(-7, -7));
}

}  // namespace
}  // namespace fresco::calib
