// Texture alignment refinement (paper §3.5) against known 2D motions: the estimated
// buffer_from_warped is compared with the motion that made the warped frame, the chosen
// model with the one the data needs, and the fall-backs with the cases that call for them.
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "pipeline/paint/refine_alignment.h"
#include "pipeline/paint/refine_pose.h"
#include "tests/paint/frontal_wall.h"

namespace fresco {
namespace {

// A buffer full of texture (blurred noise), all painted.
cv::Mat TexturedBuffer(int width = 320, int height = 240, unsigned seed = 5) {
  cv::Mat noise(height, width, CV_8UC3);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  cv::Mat blurred;
  cv::GaussianBlur(noise, blurred, cv::Size(0, 0), 2.0);
  cv::normalize(blurred, blurred, 0, 255, cv::NORM_MINMAX);
  cv::Mat bgra;
  cv::cvtColor(blurred, bgra, cv::COLOR_BGR2BGRA);
  return bgra;
}

// The warped frame: the buffer's content moved by `buffer_from_warped`^-1 (so that the
// correct refinement is `buffer_from_warped`), valid everywhere it has content.
struct Warped {
  cv::Mat bgr, valid, quality;
};
Warped MakeWarped(const cv::Mat& buffer_bgra, const cv::Matx33d& buffer_from_warped) {
  Warped w;
  cv::Mat bgr;
  cv::cvtColor(buffer_bgra, bgr, cv::COLOR_BGRA2BGR);
  // warped(x) = buffer(buffer_from_warped * x)
  cv::warpPerspective(bgr, w.bgr, cv::Mat(buffer_from_warped), bgr.size(),
                      cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_CONSTANT);
  cv::Mat ones(bgr.size(), CV_8U, cv::Scalar(255));
  cv::warpPerspective(ones, w.valid, cv::Mat(buffer_from_warped), bgr.size(),
                      cv::INTER_NEAREST | cv::WARP_INVERSE_MAP, cv::BORDER_CONSTANT);
  cv::erode(w.valid, w.valid, cv::Mat(), cv::Point(-1, -1), 2);
  w.quality = cv::Mat(bgr.size(), CV_32F, cv::Scalar(1));
  return w;
}

cv::Matx33d Similarity(double angle_deg, double scale, double tx, double ty, cv::Point2d c) {
  const double a = angle_deg * M_PI / 180, s = scale;
  // About centre c: x' = s R (x - c) + c + t
  const double r00 = s * std::cos(a), r01 = -s * std::sin(a), r10 = s * std::sin(a),
               r11 = s * std::cos(a);
  return cv::Matx33d(r00, r01, c.x - r00 * c.x - r01 * c.y + tx, r10, r11,
                     c.y - r10 * c.x - r11 * c.y + ty, 0, 0, 1);
}

// Largest distance between where two transforms put the points of a rectangle.
double MaxDifference(const cv::Matx33d& a, const cv::Matx33d& b, const cv::Rect& r) {
  double worst = 0;
  for (int y = r.y; y <= r.br().y; y += r.height / 8)
    for (int x = r.x; x <= r.br().x; x += r.width / 8) {
      const cv::Vec3d p(x, y, 1), pa = a * p, pb = b * p;
      worst =
          std::max(worst, std::hypot(pa[0] / pa[2] - pb[0] / pb[2], pa[1] / pa[2] - pb[1] / pb[2]));
    }
  return worst;
}

RefineOptions Robust() {
  RefineOptions o;
  o.mode = RefineMode::kRobust;
  return o;
}

TEST(Refine, TranslationIsRecoveredSubTexelAndModelledAsTranslation) {
  const cv::Mat buffer = TexturedBuffer();
  const cv::Matx33d truth(1, 0, 1.7, 0, 1, -2.3, 0, 0, 1);
  const Warped w = MakeWarped(buffer, truth);
  const RefineEstimate e = EstimateRefinement(w.bgr, w.valid, buffer, Robust());
  ASSERT_TRUE(e.applied) << e.fallback;
  EXPECT_EQ(e.model, MotionModel::kTranslation);
  EXPECT_LT(MaxDifference(e.buffer_from_warped, truth, e.region), 0.1);
  EXPECT_NEAR(e.residual_before_px, std::hypot(1.7, 2.3), 0.2);
  EXPECT_LT(e.residual_after_px, 0.1);
  EXPECT_GE(e.inliers, 50);
  // Texture that does not repeat: few matches dropped as ambiguous (random look-alikes).
  EXPECT_LT(e.ambiguous, 0.05 * (e.matches + e.ambiguous)) << e.ambiguous << " of " << e.matches;
  // Warping again makes the frame agree with the buffer.
  Warped again{w.bgr.clone(), w.valid.clone(), w.quality.clone()};
  ApplyRefinement(e, cv::Rect(), &again.bgr, &again.valid, &again.quality);
  cv::Mat buffer_bgr, diff_before, diff_after;
  cv::cvtColor(buffer, buffer_bgr, cv::COLOR_BGRA2BGR);
  const cv::Rect inner(20, 20, 280, 200);
  cv::absdiff(w.bgr(inner), buffer_bgr(inner), diff_before);
  cv::absdiff(again.bgr(inner), buffer_bgr(inner), diff_after);
  EXPECT_LT(cv::mean(diff_after)[0], 0.3 * cv::mean(diff_before)[0]);
}

TEST(Refine, ModelSelectionPicksWhatTheMotionNeeds) {
  const cv::Mat buffer = TexturedBuffer(400, 300);
  const cv::Point2d c(200, 150);
  struct Case {
    cv::Matx33d truth;
    MotionModel expected;
  };
  cv::Matx33d homography = Similarity(0.5, 1.0, 1.0, 0.5, c);
  homography(2, 0) = 2e-5;
  homography(2, 1) = -3e-5;
  const Case cases[] = {
      {cv::Matx33d::eye(), MotionModel::kNone},
      {cv::Matx33d(1, 0, 2.5, 0, 1, 1.0, 0, 0, 1), MotionModel::kTranslation},
      {Similarity(1.0, 1.02, 1.0, -0.5, c), MotionModel::kSimilarity},
      {cv::Matx33d(1.02, 0.015, -3.0, -0.01, 0.99, 2.0, 0, 0, 1), MotionModel::kAffine},
      {homography, MotionModel::kHomography},
  };
  for (const Case& k : cases) {
    const Warped w = MakeWarped(buffer, k.truth);
    const RefineEstimate e = EstimateRefinement(w.bgr, w.valid, buffer, Robust());
    EXPECT_EQ(MotionModelName(e.model), MotionModelName(k.expected)) << e.fallback;
    if (k.expected != MotionModel::kNone) {
      ASSERT_TRUE(e.applied) << MotionModelName(k.expected) << ": " << e.fallback;
      EXPECT_LT(MaxDifference(e.buffer_from_warped, k.truth, e.region), 0.15)
          << MotionModelName(k.expected);
    } else {
      EXPECT_FALSE(e.applied);
      EXPECT_EQ(e.fallback, "none needed (model selection)");
    }
  }
}

TEST(Refine, MoversDoNotDragTheRobustFitButDragThePapers) {
  const cv::Mat buffer = TexturedBuffer(400, 300);
  const cv::Matx33d truth(1, 0, 1.5, 0, 1, 1.0, 0, 0, 1);
  Warped w = MakeWarped(buffer, truth);
  // A "mover": a textured patch in the warped frame that is displaced differently.
  const cv::Mat other = TexturedBuffer(400, 300, 99);
  cv::Mat patch;
  cv::cvtColor(other(cv::Rect(40, 40, 150, 120)), patch, cv::COLOR_BGRA2BGR);
  patch.copyTo(w.bgr(cv::Rect(44, 43, 150, 120)));
  cv::Mat buffer_with_mover = buffer.clone();
  other(cv::Rect(40, 40, 150, 120)).copyTo(buffer_with_mover(cv::Rect(40, 40, 150, 120)));
  const RefineEstimate robust = EstimateRefinement(w.bgr, w.valid, buffer_with_mover, Robust());
  ASSERT_TRUE(robust.applied) << robust.fallback;
  EXPECT_LT(robust.inliers, robust.matches);  // the mover's matches are outliers
  EXPECT_LT(MaxDifference(robust.buffer_from_warped, truth, robust.region), 0.2);
  RefineOptions paper;
  paper.mode = RefineMode::kPaper;
  const RefineEstimate p = EstimateRefinement(w.bgr, w.valid, buffer_with_mover, paper);
  ASSERT_TRUE(p.applied) << p.fallback;
  EXPECT_EQ(p.model, MotionModel::kAffine);
  EXPECT_GT(MaxDifference(p.buffer_from_warped, truth, p.region),
            2 * MaxDifference(robust.buffer_from_warped, truth, robust.region));
}

TEST(Refine, PaperModeRecoversAnIntegerShift) {
  const cv::Mat buffer = TexturedBuffer();
  const cv::Matx33d truth(1, 0, 3, 0, 1, -2, 0, 0, 1);
  const Warped w = MakeWarped(buffer, truth);
  RefineOptions paper;
  paper.mode = RefineMode::kPaper;
  const RefineEstimate e = EstimateRefinement(w.bgr, w.valid, buffer, paper);
  ASSERT_TRUE(e.applied) << e.fallback;
  EXPECT_LT(MaxDifference(e.buffer_from_warped, truth, e.region), 0.3);
}

TEST(Refine, ExtremesFallBackToNoCorrectionAndSaySo) {
  const cv::Mat buffer = TexturedBuffer(400, 300);
  // Textureless.
  const cv::Mat flat(300, 400, CV_8UC4, cv::Scalar(120, 120, 120, 255));
  Warped w = MakeWarped(flat, cv::Matx33d(1, 0, 1, 0, 1, 1, 0, 0, 1));
  RefineEstimate e = EstimateRefinement(w.bgr, w.valid, flat, Robust());
  EXPECT_FALSE(e.applied);
  EXPECT_EQ(e.fallback, "too few corners (textureless?)");
  // Texture only along one line: collinear corners.
  cv::Mat line_only = flat.clone();
  buffer(cv::Rect(0, 140, 400, 6)).copyTo(line_only(cv::Rect(0, 140, 400, 6)));
  w = MakeWarped(line_only, cv::Matx33d(1, 0, 1, 0, 1, 0.5, 0, 0, 1));
  e = EstimateRefinement(w.bgr, w.valid, line_only, Robust());
  EXPECT_FALSE(e.applied);
  EXPECT_TRUE(e.fallback == "corners (nearly) collinear" || e.fallback == "too few matches")
      << e.fallback;
  // A shift larger than the search window.
  RefineOptions narrow = Robust();
  narrow.search_px = 4;
  w = MakeWarped(buffer, cv::Matx33d(1, 0, 9, 0, 1, 0, 0, 0, 1));
  e = EstimateRefinement(w.bgr, w.valid, buffer, narrow);
  EXPECT_FALSE(e.applied);
  // A fit that would scale the image by 7 %.
  w = MakeWarped(buffer, Similarity(0, 1.07, 0, 0, cv::Point2d(200, 150)));
  RefineOptions wide = Robust();
  wide.search_px = 30;
  e = EstimateRefinement(w.bgr, w.valid, buffer, wide);
  EXPECT_FALSE(e.applied);
  EXPECT_EQ(e.fallback, "fit would scale or shear the image") << e.fallback;
  // Nothing painted yet.
  cv::Mat empty = buffer.clone();
  empty.setTo(cv::Scalar(255, 255, 255, 0));
  w = MakeWarped(buffer, cv::Matx33d::eye());
  e = EstimateRefinement(w.bgr, w.valid, empty, Robust());
  EXPECT_FALSE(e.applied);
  EXPECT_EQ(e.fallback, "too little painted overlap");
  // Off.
  RefineOptions off;
  off.mode = RefineMode::kOff;
  e = EstimateRefinement(w.bgr, w.valid, buffer, off);
  EXPECT_EQ(e.fallback, "off");
}

TEST(Refine, DebugImagesHaveTheBufferSize) {
  const cv::Mat buffer = TexturedBuffer();
  const Warped w = MakeWarped(buffer, cv::Matx33d(1, 0, 1, 0, 1, 1, 0, 0, 1));
  const RefineEstimate e = EstimateRefinement(w.bgr, w.valid, buffer, Robust());
  EXPECT_EQ(DrawRefinementMatches(w.bgr, e).size(), w.bgr.size());
  const cv::Mat heat = ResidualHeatMap(w.bgr, w.valid, buffer, e.region);
  EXPECT_EQ(heat.size(), e.region.size());
}

// Repetitive buffers (an extreme): a texture that repeats with a period shorter than the search
// window matches equally well one period away, so the nearest match may be the wrong one. A
// shift of 0.6 period puts the wrong copy nearest (0.4 period the other way). Whatever the
// shift, the estimate must be the true one or none, with the reason: never a whole period off.

// Blurred noise repeated every `period` texels along x (and along y when period.height > 0).
cv::Mat RepeatedNoise(cv::Size period, int width, int height, unsigned seed) {
  cv::Mat tile(period.height > 0 ? period.height : height, period.width, CV_8UC3);
  cv::RNG rng(seed);
  rng.fill(tile, cv::RNG::UNIFORM, 0, 255);
  cv::Mat noise, blurred, bgra;
  cv::repeat(tile, height / tile.rows + 1, width / tile.cols + 1, noise);
  cv::GaussianBlur(noise, blurred, cv::Size(0, 0), 1.2);  // of a periodic image: periodic
  cv::normalize(blurred(cv::Rect(0, 0, width, height)), blurred, 0, 255, cv::NORM_MINMAX);
  cv::cvtColor(blurred, bgra, cv::COLOR_BGR2BGRA);
  return bgra;
}

// Bricks 12 x 6 texels, rows staggered by half a brick, mortar 1 texel: periods (12, 0), (6, 6).
cv::Mat Bricks(int width, int height) {
  cv::Mat image(height, width, CV_8UC3, cv::Scalar(70, 80, 90));
  for (int row = 0; row * 6 < height; ++row)
    for (int x = (row % 2) * 6 - 12; x < width; x += 12)
      cv::rectangle(image, cv::Rect(x + 1, row * 6 + 1, 11, 5), cv::Scalar(60, 90, 170), cv::FILLED);
  cv::Mat blurred, bgra;
  cv::GaussianBlur(image, blurred, cv::Size(0, 0), 0.7);
  cv::cvtColor(blurred, bgra, cv::COLOR_BGR2BGRA);
  return bgra;
}

const char kAmbiguous[] = "repetitive texture: matches ambiguous within the search window";

RefineOptions WithMode(RefineMode mode) {
  RefineOptions o;
  o.mode = mode;
  return o;
}

TEST(Refine, RepetitiveTextureIsRegisteredTrulyOrRefusedNeverAPeriodOff) {
  struct Buffer {
    const char* name;
    cv::Mat bgra;
    double period_x;
  };
  const Buffer buffers[] = {
      {"columns of period 8", RepeatedNoise(cv::Size(8, 0), 320, 240, 11), 8},
      {"tiles of 10 x 10", RepeatedNoise(cv::Size(10, 10), 320, 240, 12), 10},
      {"bricks 12 x 6", Bricks(320, 240), 12},
  };
  for (const Buffer& buffer : buffers) {
    for (const RefineMode mode : {RefineMode::kPaper, RefineMode::kRobust}) {
      // Paper mode matches whole texels: half a texel of rounding on top of the interpolation.
      const double tolerance = mode == RefineMode::kPaper ? 0.6 : 0.3;
      for (const double fraction : {0.2, 0.45, 0.6}) {
        const cv::Matx33d truth(1, 0, fraction * buffer.period_x, 0, 1, 0.4, 0, 0, 1);
        const Warped w = MakeWarped(buffer.bgra, truth);
        const RefineEstimate e = EstimateRefinement(w.bgr, w.valid, buffer.bgra, WithMode(mode));
        const std::string what = std::string(buffer.name) +
                                 (mode == RefineMode::kPaper ? ", paper" : ", robust") +
                                 ", shift " + std::to_string(fraction) + " period";
        if (e.applied) {
          EXPECT_LT(MaxDifference(e.buffer_from_warped, truth, e.region), tolerance) << what;
        } else {
          EXPECT_FALSE(e.registered) << what;  // no sample for the anchor either
          EXPECT_EQ(e.fallback, kAmbiguous) << what;
        }
      }
    }
  }
}

TEST(Refine, RepetitionLongerThanTheSearchWindowIsStillRegistered) {
  // Period 32: one copy only within +-12 texels of the shift, so nothing is ambiguous.
  const cv::Mat buffer = RepeatedNoise(cv::Size(32, 32), 320, 240, 13);
  const cv::Matx33d truth(1, 0, 6.4, 0, 1, -2.2, 0, 0, 1);
  const Warped w = MakeWarped(buffer, truth);
  for (const RefineMode mode : {RefineMode::kPaper, RefineMode::kRobust}) {
    const RefineEstimate e = EstimateRefinement(w.bgr, w.valid, buffer, WithMode(mode));
    ASSERT_TRUE(e.applied) << e.fallback;
    EXPECT_LT(MaxDifference(e.buffer_from_warped, truth, e.region),
              mode == RefineMode::kPaper ? 0.6 : 0.3);
    EXPECT_EQ(e.ambiguous, 0);
  }
}

// The pose path: a 3.2 m x 2.4 m wall at 1 cm texels, 2.5 m in front of the camera, in
// columns of period 8 texels; the pose is off by a rotation that shifts the wall by 0.2, 0.45
// and 0.6 period (more towards the sides: perspective). Unchecked, the 0.6 case gave a pose
// correction (rotation + translation) that put the wall 8.0 texels off: one period.
TEST(Refine, RepetitiveWallGivesNoPoseCorrectionAPeriodOff) {
  const BaseBuffer wall = FrontalWall(320, 240, 0.01, 2.5);
  const Camera camera = Camera::FromParams(LensModel::kPinhole, 320, 240, {228, 228, 159.5, 119.5});
  const Rigid3d given;
  const cv::Mat texture = RepeatedNoise(cv::Size(8, 0), wall.width, wall.height, 14);
  for (const double fraction : {0.2, 0.45, 0.6}) {
    // About y: 1 rad moves the wall by 2.5 m = 250 texels.
    const Rigid3d truth(
        Rigid3d::QuaternionFromAxisAngle(Eigen::Vector3d(0, fraction * 8 / 250.0, 0)),
        Eigen::Vector3d::Zero());
    cv::Matx33d H;
    ASSERT_TRUE(BufferCorrectionFromPose(wall, camera, given, truth * given,
                                         cv::Rect(0, 0, wall.width, wall.height), &H));
    const Warped w = MakeWarped(texture, H);
    const RefineEstimate e = EstimateRefinement(w.bgr, w.valid, texture, Robust());
    std::vector<PoseMatch> matches;
    AppendPoseMatches(wall, camera, given, e, &matches);
    const PoseCorrection pose = EstimatePoseCorrection(matches, camera, given, Robust());
    if (pose.applied) {  // the wall's correction from the pose: where it puts the texture
      cv::Matx33d from_pose;
      ASSERT_TRUE(BufferCorrectionFromPose(wall, camera, given, pose.delta * given,
                                           cv::Rect(0, 0, wall.width, wall.height), &from_pose));
      EXPECT_LT(MaxDifference(from_pose, H, cv::Rect(0, 0, wall.width, wall.height)), 0.3)
          << fraction << ": " << pose.model;
    } else {
      EXPECT_FALSE(pose.fallback.empty());
      EXPECT_EQ(e.fallback, kAmbiguous) << fraction;
    }
  }
}

}  // namespace
}  // namespace fresco
