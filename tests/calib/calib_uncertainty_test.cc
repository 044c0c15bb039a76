// Projection uncertainty (calib/uncertainty.h) against Monte Carlo re-solves of synthetic
// boards through a known camera, its behaviour with more data, and the data traps of
// calibration (few images, boards on one side of the imager or only at its centre, heavy
// distortion, a model too simple forced on a distorted lens): each gives a clear warning.
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "calib/lens_projection.h"
#include "calib/model_select.h"
#include "tests/calib/synthetic_boards.h"

namespace fresco::calib {
namespace {

using testing::AllWarnings;
using testing::Placement;
using testing::SolveSynthetic;
using testing::Spec;
using testing::SyntheticCapture;
using testing::SyntheticPose;
using testing::SyntheticViews;

SyntheticCapture MildOpenCV4() {
  SyntheticCapture capture;
  capture.lensmodel = "LENSMODEL_OPENCV4";
  capture.intrinsics = {600, 605, 322, 238, -0.12, 0.06, 0.0005, -0.0003};
  return capture;
}

Eigen::Matrix3d Rotation(const std::array<double, 6>& rt) {
  const Eigen::Vector3d r(rt[0], rt[1], rt[2]);
  return Eigen::AngleAxisd(r.norm(), r.normalized()).toRotationMatrix();
}

double WorstDirectionStdev(const Eigen::Matrix2d& c) {
  return std::sqrt((c(0, 0) + c(1, 1)) / 2 +
                   std::sqrt((c(0, 0) - c(1, 1)) * (c(0, 0) - c(1, 1)) / 4 + c(1, 0) * c(1, 0)));
}

// The predicted 1-sigma matches the spread of the projections of fixed points over 30 noise
// draws, each solved anew: a point fixed to the true boards (at the boards' range, seen at a
// pixel) is mapped through each solve's own board poses (their mean, as mrcal does) and
// projected with its own intrinsics.
TEST(ProjectionUncertaintyTest, MatchesMonteCarloAndIsLowestAtTheCentre) {
  const BoardSpec spec = Spec("chessboard:10x7:0.03");
  const SyntheticCapture truth = MildOpenCV4();
  const CalibrationRun run = SolveSynthetic(SyntheticViews(spec, truth), spec, 640, 480, "opencv4",
                                            /*cross_validate=*/false);
  const UncertaintyMap& u = run.uncertainty;
  ASSERT_GT(u.centre_px, 0);
  std::cout << "centre " << u.centre_px << " px, corners " << u.corners_px[0] << " "
            << u.corners_px[1] << " " << u.corners_px[2] << " " << u.corners_px[3]
            << " px, observed median " << u.median_observed_px << " px, max " << u.max_px
            << " px at " << u.range_m << " m\n";
  for (double c : u.corners_px) EXPECT_GT(c, 2 * u.centre_px);
  EXPECT_LT(u.centre_px, u.median_observed_px);
  EXPECT_NEAR(u.range_m, 0.42, 0.05);
  EXPECT_GT(run.uncertainty_at_infinity.centre_px, 0);

  const std::vector<Eigen::Vector2d> pixels = {{319.5, 239.5}, {20, 20}, {600, 440}, {450, 150}};
  std::vector<Eigen::Vector3d> rays;
  ASSERT_TRUE(UnprojectPixels(truth.lensmodel, truth.intrinsics, pixels, &rays));
  // Each point in each true board's frame.
  std::vector<std::vector<Eigen::Vector3d>> in_board(pixels.size());
  for (size_t k = 0; k < pixels.size(); ++k)
    for (int v = 0; v < truth.views; ++v) {
      const auto rt = SyntheticPose(v, spec, truth);
      const Eigen::Vector3d p = rays[k].normalized() * u.range_m;
      in_board[k].push_back(Rotation(rt).transpose() * (p - Eigen::Vector3d(rt[3], rt[4], rt[5])));
    }
  constexpr int kDraws = 30;
  std::vector<std::vector<Eigen::Vector2d>> q(pixels.size());
  for (int draw = 0; draw < kDraws; ++draw) {
    SyntheticCapture capture = truth;
    capture.seed = 100 + draw;
    const CalibrationRun r =
        SolveSynthetic(SyntheticViews(spec, capture), spec, 640, 480, "opencv4", false);
    const SolveResult& fit = r.Chosen().fit;
    for (size_t k = 0; k < pixels.size(); ++k) {
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (int v = 0; v < truth.views; ++v) {
        const auto& rt = fit.views[v].rt_cam_from_board;
        mean += Rotation(rt) * in_board[k][v] + Eigen::Vector3d(rt[3], rt[4], rt[5]);
      }
      std::vector<Eigen::Vector2d> projected;
      ASSERT_TRUE(ProjectPoints(fit.lensmodel, fit.intrinsics, {mean / truth.views}, &projected));
      q[k].push_back(projected[0]);
    }
  }
  for (size_t k = 0; k < pixels.size(); ++k) {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& x : q[k]) mean += x / kDraws;
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (const auto& x : q[k]) cov += (x - mean) * (x - mean).transpose() / (kDraws - 1);
    const double empirical = WorstDirectionStdev(cov);
    const double predicted =
        ProjectionUncertainty_px(run.Chosen().fit, pixels[k], u.range_m, u.sigma_px);
    std::cout << "pixel (" << pixels[k].transpose() << "): predicted " << predicted
              << " px, Monte Carlo " << empirical << " px\n";
    EXPECT_NEAR(predicted / empirical, 1.0, 0.35) << k;
  }
}

TEST(ProjectionUncertaintyTest, ShrinksWithMoreImages) {
  const BoardSpec spec = Spec("chessboard:10x7:0.03");
  SyntheticCapture few = MildOpenCV4(), many = MildOpenCV4();
  few.views = 8;
  many.views = 32;
  const CalibrationRun a =
      SolveSynthetic(SyntheticViews(spec, few), spec, 640, 480, "opencv4", false);
  const CalibrationRun b =
      SolveSynthetic(SyntheticViews(spec, many), spec, 640, 480, "opencv4", false);
  std::cout << "8 views: centre " << a.uncertainty.centre_px << " px, max " << a.uncertainty.max_px
            << " px; 32 views: centre " << b.uncertainty.centre_px << " px, max "
            << b.uncertainty.max_px << " px\n";
  // Four times the data: about half the uncertainty.
  EXPECT_LT(b.uncertainty.centre_px, 0.7 * a.uncertainty.centre_px);
  EXPECT_LT(b.uncertainty.median_observed_px, 0.7 * a.uncertainty.median_observed_px);
  EXPECT_LT(b.uncertainty.max_px, 0.7 * a.uncertainty.max_px);
}

TEST(DataTrapsTest, FewImagesWarnAndAreUncertain) {
  const BoardSpec spec = Spec("chessboard:10x7:0.03");
  SyntheticCapture capture = MildOpenCV4();
  capture.views = 4;
  const CalibrationRun run = SolveSynthetic(SyntheticViews(spec, capture), spec, 640, 480, "auto");
  const std::string all = AllWarnings(run);
  std::cout << all;
  EXPECT_NE(all.find("only 4 images"), std::string::npos) << all;
  EXPECT_NE(all.find("too few to cross-validate"), std::string::npos) << all;
  const CalibrationRun more = SolveSynthetic(SyntheticViews(spec, MildOpenCV4()), spec, 640, 480,
                                             run.Chosen().short_name, false);
  EXPECT_GT(run.uncertainty.median_observed_px, 1.5 * more.uncertainty.median_observed_px);
}

TEST(DataTrapsTest, BoardsOnOneSideWarnAndTheOtherSideIsUncertain) {
  const BoardSpec spec = Spec("chessboard:6x5:0.02");
  SyntheticCapture capture = MildOpenCV4();
  capture.placement = Placement::kLeftSide;
  capture.views = 16;
  const auto views = SyntheticViews(spec, capture);
  for (const BoardView& v : views)
    for (const CornerObservation& c : v.corners) ASSERT_LT(c.pixel.x(), 320) << v.name;
  const CalibrationRun run = SolveSynthetic(views, spec, 640, 480, "opencv4", false);
  const std::string all = AllWarnings(run);
  std::cout << all;
  EXPECT_NE(all.find("no corner observed in the top-right quarter"), std::string::npos) << all;
  EXPECT_NE(all.find("no corner observed in the bottom-right quarter"), std::string::npos) << all;
  EXPECT_NE(all.find("projection uncertainty at"), std::string::npos) << all;
  const UncertaintyMap& u = run.uncertainty;
  EXPECT_GT(u.corners_px[1], 3 * u.corners_px[0]);  // right side far less known than left
  EXPECT_GT(u.corners_px[3], 3 * u.corners_px[2]);
}

TEST(DataTrapsTest, BoardOnlyAtTheCentreIsUncertainAtTheEdges) {
  const BoardSpec spec = Spec("chessboard:5x4:0.02");
  SyntheticCapture capture = MildOpenCV4();
  capture.placement = Placement::kCentre;
  capture.views = 12;
  const CalibrationRun run =
      SolveSynthetic(SyntheticViews(spec, capture), spec, 640, 480, "opencv4", false);
  const std::string all = AllWarnings(run);
  std::cout << all;
  EXPECT_NE(all.find("cover only"), std::string::npos) << all;
  EXPECT_NE(all.find("fronto-parallel"), std::string::npos) << all;
  EXPECT_NE(all.find("reaches"), std::string::npos) << all;
  EXPECT_GT(run.uncertainty.max_px, kMaxUncertaintyPx);
  for (double c : run.uncertainty.corners_px) EXPECT_GT(c, 5 * run.uncertainty.centre_px);
}

// A wide lens with heavy barrel distortion (rational opencv8, ~95 deg across): the simple
// models leave systematic residuals and `auto` takes a model that projects like the truth;
// forcing pinhole on it is written, but with a warning against the opencv8 yardstick.
SyntheticCapture HeavyDistortion() {
  SyntheticCapture capture;
  capture.lensmodel = "LENSMODEL_OPENCV8";
  capture.intrinsics = {300, 301, 318, 243, -0.45, 0.22, 0.0008, -0.0005, -0.05, 0.05, -0.02, 0.01};
  capture.distance_m = 0.3;
  capture.views = 16;
  return capture;
}

TEST(DataTrapsTest, HeavyDistortionAutoFindsTheLens) {
  const BoardSpec spec = Spec("chessboard:10x7:0.03");
  const SyntheticCapture truth = HeavyDistortion();
  const auto views = SyntheticViews(spec, truth);
  const CalibrationRun run = SolveSynthetic(views, spec, 640, 480, "auto");
  for (const ModelTrial& t : run.choice.trials)
    std::cout << t.short_name << ": sigma " << t.fit.noise_sigma_px << " px, cross-validation "
              << t.cross_validation_px << " px" << (t.fits ? " fits" : "") << "\n";
  std::cout << "chosen " << run.Chosen().short_name << "\n" << AllWarnings(run);
  EXPECT_FALSE(run.choice.trials[0].fits);  // pinhole
  EXPECT_FALSE(run.choice.trials[1].fits);  // opencv4
  const SolveResult& fit = run.Chosen().fit;
  const double diff = ProjectionDifference_px(truth.lensmodel, truth.intrinsics, fit.lensmodel,
                                              fit.intrinsics, ObservedPixels(views, 640, 480));
  std::cout << "projection difference to the truth " << diff << " px\n";
  EXPECT_LT(diff, 0.15);
  EXPECT_NEAR(fit.noise_sigma_px, truth.noise_px, 0.03);
}

TEST(DataTrapsTest, ForcedTooSimpleModelWarns) {
  const BoardSpec spec = Spec("chessboard:10x7:0.03");
  const auto views = SyntheticViews(spec, HeavyDistortion());
  const CalibrationRun run = SolveSynthetic(views, spec, 640, 480, "opencv4", false);
  const std::string all = AllWarnings(run);
  std::cout << all;
  EXPECT_NE(all.find("the requested model opencv4 leaves systematic residuals"), std::string::npos)
      << all;
  // A model that fits is not warned about.
  const auto mild = SyntheticViews(spec, MildOpenCV4());
  const std::string none = AllWarnings(SolveSynthetic(mild, spec, 640, 480, "opencv4", false));
  EXPECT_EQ(none.find("systematic"), std::string::npos) << none;
}

// ---- Cross-validation (model_select.h): the halves' difference against what their own
// uncertainty predicts. ---------------------------------------------------------------------

// A model that fits the lens: over several noise draws the halves differ about as much as
// their covariances predict (the rule allows 3x), so it is supported.
TEST(CrossValidationTest, HalvesDifferAsTheirUncertaintyPredicts) {
  const BoardSpec spec = Spec("chessboard:10x7:0.03");
  double sum_ratio = 0;
  const int kDraws = 6;
  for (int draw = 0; draw < kDraws; ++draw) {
    SyntheticCapture truth = MildOpenCV4();
    truth.seed = 100 + draw;
    const CalibrationRun run =
        SolveSynthetic(SyntheticViews(spec, truth), spec, 640, 480, "opencv4", true);
    const ModelTrial& t = run.choice.trials[0];
    ASSERT_GT(t.cross_validation_expected_px, 0);
    const double ratio = t.cross_validation_px / t.cross_validation_expected_px;
    std::cout << "draw " << draw << ": halves differ " << t.cross_validation_px
              << " px, predicted " << t.cross_validation_expected_px << " px, ratio " << ratio
              << "\n";
    EXPECT_TRUE(t.supported);
    EXPECT_DOUBLE_EQ(t.noise_inflation, 1.0);  // chessboard corners are independent
    sum_ratio += ratio;
  }
  std::cout << "mean ratio " << sum_ratio / kDraws << "\n";
  EXPECT_GT(sum_ratio / kDraws, 0.4);
  EXPECT_LT(sum_ratio / kDraws, 1.6);
}

// AprilTag-like noise: each tag's 4 corners share a shift (0.2 px) on top of independent
// noise (0.1 px), so their correlation is 0.8. It is measured from the residuals, the
// uncertainty is inflated by sqrt(1 + 3 rho), and the true model class is still supported.
TEST(CrossValidationTest, CorrelatedTagNoiseIsMeasuredAndInflatesTheUncertainty) {
  const BoardSpec spec = Spec("aprilgrid:6x6:0.088:0.3");
  SyntheticCapture truth = MildOpenCV4();
  truth.distance_m = 1.3;
  truth.noise_px = 0.1;
  truth.tag_shift_px = 0.2;
  const double rho = 0.2 * 0.2 / (0.2 * 0.2 + 0.1 * 0.1);
  const CalibrationRun run =
      SolveSynthetic(SyntheticViews(spec, truth), spec, 640, 480, "opencv4", true);
  const ModelTrial& t = run.choice.trials[0];
  std::cout << "rho " << run.corner_correlation << " (truth " << rho << "), inflation "
            << t.noise_inflation << ", halves differ " << t.cross_validation_px
            << " px, predicted " << t.cross_validation_expected_px << " px\n";
  EXPECT_NEAR(run.corner_correlation, rho, 0.1);
  EXPECT_NEAR(t.noise_inflation, std::sqrt(1 + 3 * rho), 0.15);
  EXPECT_NEAR(run.noise_inflation, t.noise_inflation, 1e-9);
  EXPECT_TRUE(t.supported);
  // Independent noise of the same variance: no inflation.
  SyntheticCapture independent = truth;
  independent.tag_shift_px = 0;
  independent.noise_px = std::sqrt(0.2 * 0.2 + 0.1 * 0.1);
  const CalibrationRun plain =
      SolveSynthetic(SyntheticViews(spec, independent), spec, 640, 480, "opencv4", true);
  std::cout << "independent: rho " << plain.corner_correlation << ", inflation "
            << plain.choice.trials[0].noise_inflation << "\n";
  EXPECT_NEAR(plain.corner_correlation, 0, 0.1);
  EXPECT_LT(plain.choice.trials[0].noise_inflation, 1.15);
}

// `auto` solves a model's halves only where the choice depends on them: the choice, and every
// verdict it rests on, is the same as with every model's halves solved.
TEST(CrossValidationTest, SkippingUnneededHalvesChoosesTheSame) {
  const BoardSpec spec = Spec("chessboard:10x7:0.03");
  SyntheticCapture pinhole;
  for (const SyntheticCapture& truth : {pinhole, MildOpenCV4(), HeavyDistortion()}) {
    SCOPED_TRACE(truth.lensmodel);
    const auto views = SyntheticViews(spec, truth);
    CalibrationSeed seed;
    ASSERT_TRUE(SeedCalibration(views, spec, 640, 480, &seed).ok());
    SelectOptions lazy, all;
    all.all_halves = true;
    int lazy_solves = 0;
    lazy.progress = [&](int, int, const std::string&) { ++lazy_solves; };
    ModelChoice a, b;
    ASSERT_TRUE(FitLensModels(views, spec, 640, 480, seed, lazy, &a).ok());
    ASSERT_TRUE(FitLensModels(views, spec, 640, 480, seed, all, &b).ok());
    ASSERT_EQ(a.trials.size(), b.trials.size());
    std::cout << truth.lensmodel << ": chosen " << a.trials[a.chosen].short_name << " with "
              << lazy_solves << " solves (all halves: " << 3 * a.trials.size() << ")\n";
    EXPECT_EQ(a.chosen, b.chosen);
    EXPECT_LT(lazy_solves, static_cast<int>(3 * a.trials.size()));
    for (size_t i = 0; i < a.trials.size(); ++i) {
      EXPECT_FALSE(b.trials[i].halves_skipped);
      if (a.trials[i].halves_skipped) continue;
      EXPECT_EQ(a.trials[i].supported, b.trials[i].supported) << a.trials[i].short_name;
      EXPECT_DOUBLE_EQ(a.trials[i].cross_validation_px, b.trials[i].cross_validation_px);
    }
    EXPECT_TRUE(a.trials[a.chosen].supported);
    EXPECT_FALSE(a.trials[a.chosen].halves_skipped);
  }
}

}  // namespace
}  // namespace fresco::calib
