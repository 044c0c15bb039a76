#include "calib/model_select.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "calib/lens_projection.h"
#include "calib/noise_correlation.h"
#include "calib/uncertainty.h"

namespace fresco::calib {
namespace {

constexpr int kSplinedNx = 10;       // control points across; Ny follows the aspect ratio
constexpr double kFovMargin = 1.15;  // splined grid reaches 15 % beyond the seed's view
constexpr int kMinViewsPerHalf = 3;

std::string Fixed(double value, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", digits, value);
  return buffer;
}

CalibrationSeed SubsetSeed(const CalibrationSeed& seed, const std::vector<int>& indices) {
  CalibrationSeed out = seed;
  out.rt_cam_from_board.clear();
  for (int i : indices) out.rt_cam_from_board.push_back(seed.rt_cam_from_board[i]);
  return out;
}

// Solves each half alone and compares their projections over `observed` with what their own
// uncertainty (at infinity, as the diff fits a rotation only; corner noise times the trial's
// AprilTag inflation) predicts for two independent solves of a model that fits the lens.
void CrossValidate(const std::vector<BoardView>& views, const BoardSpec& spec, int width,
                   int height, const CalibrationSeed& seed, const std::vector<int> (&halves)[2],
                   const SolveOptions& solve, const std::vector<Eigen::Vector2d>& observed,
                   const std::function<void(const std::string&)>& starting, ModelTrial* trial) {
  SolveResult half_fit[2];
  SolveOptions half = solve;
  half.compute_uncertainty = true;
  half.noise_inflation = trial->noise_inflation;
  for (int h = 0; h < 2; ++h) {
    std::vector<BoardView> subset;
    for (int i : halves[h]) subset.push_back(views[i]);
    starting(trial->short_name + ": half " + std::to_string(h + 1) + " (" +
             std::to_string(subset.size()) + " images)");
    if (!SolveIntrinsics(subset, spec, width, height, SubsetSeed(seed, halves[h]), half,
                         &half_fit[h])
             .ok())
      return;
  }
  std::vector<int> compared;
  std::vector<Eigen::Vector2d> diffs;
  if (!ProjectionDifferences_px(half_fit[0].lensmodel, half_fit[0].intrinsics,
                                half_fit[1].lensmodel, half_fit[1].intrinsics, observed,
                                &compared, &diffs))
    return;
  double diff_sum = 0;
  std::vector<Eigen::Vector2d> pixels;
  for (size_t i = 0; i < compared.size(); ++i) {
    diff_sum += diffs[i].squaredNorm();
    pixels.push_back(observed[compared[i]]);
  }
  trial->cross_validation_px = std::sqrt(diff_sum / diffs.size());
  trial->cross_validation_expected_px = ExpectedProjectionDifference_px(
      half_fit[0], half_fit[0].noise_sigma_px * trial->noise_inflation, half_fit[1],
      half_fit[1].noise_sigma_px * trial->noise_inflation, pixels);
}

}  // namespace

const std::vector<std::string>& LensModelShortNames() {
  static const std::vector<std::string> kNames = {"pinhole", "opencv4", "opencv5", "opencv8",
                                                  "splined"};
  return kNames;
}

std::string MrcalLensModelName(const std::string& short_name, const CalibrationSeed& seed,
                               int width, int height) {
  if (short_name == "pinhole") return "LENSMODEL_PINHOLE";
  if (short_name == "opencv4") return "LENSMODEL_OPENCV4";
  if (short_name == "opencv5") return "LENSMODEL_OPENCV5";
  if (short_name == "opencv8") return "LENSMODEL_OPENCV8";
  if (short_name != "splined") return "";
  // Horizontal field of view of the seed (two-term radial), with a margin.
  const std::vector<double> seed_intrinsics = {seed.fx, seed.fy, seed.cx, seed.cy,
                                               seed.k1, seed.k2, 0.0,     0.0};
  std::vector<Eigen::Vector3d> rays;
  double fov_deg = 2 * std::atan(width / 2.0 / seed.fx) * 180 / M_PI;
  if (UnprojectPixels("LENSMODEL_OPENCV4", seed_intrinsics,
                      {Eigen::Vector2d(-0.5, seed.cy), Eigen::Vector2d(width - 0.5, seed.cy)},
                      &rays) &&
      rays[0].allFinite() && rays[1].allFinite()) {
    const double angle = std::acos(std::clamp(rays[0].normalized().dot(rays[1].normalized()), -1.0, 1.0));
    if (angle > 0.1) fov_deg = angle * 180 / M_PI;
  }
  const int fov = std::clamp(static_cast<int>(std::ceil(fov_deg * kFovMargin)), 10, 170);
  const int ny = std::max(4, static_cast<int>(std::lround(kSplinedNx * height / double(width))));
  return "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=" + std::to_string(kSplinedNx) +
         "_Ny=" + std::to_string(ny) + "_fov_x_deg=" + std::to_string(fov);
}

double AgreementLimit_px(const ModelTrial& trial) {
  const double expected = trial.cross_validation_expected_px >= 0
                              ? trial.cross_validation_expected_px
                              : trial.fit.noise_sigma_px * trial.noise_inflation;
  return std::max(kAgreeFactor * expected, kAgreeFloorPx);
}

std::vector<Eigen::Vector2d> ObservedPixels(const std::vector<BoardView>& views, int width,
                                            int height) {
  const double cell = width / 16.0;
  const int nx = static_cast<int>(std::ceil(width / cell)), ny = static_cast<int>(std::ceil(height / cell));
  std::vector<bool> seen(nx * ny, false);
  for (const BoardView& v : views)
    for (const CornerObservation& c : v.corners) {
      const int i = std::clamp(static_cast<int>((c.pixel.x() + 0.5) / cell), 0, nx - 1);
      const int j = std::clamp(static_cast<int>((c.pixel.y() + 0.5) / cell), 0, ny - 1);
      seen[j * nx + i] = true;
    }
  std::vector<Eigen::Vector2d> pixels;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      if (seen[j * nx + i])
        pixels.emplace_back(std::min((i + 0.5) * cell, width - 1.0),
                            std::min((j + 0.5) * cell, height - 1.0));
  return pixels;
}

Status FitLensModels(const std::vector<BoardView>& views, const BoardSpec& spec, int width,
                     int height, const CalibrationSeed& seed, const SelectOptions& options,
                     ModelChoice* choice) {
  ModelChoice out;
  std::vector<int> halves[2];
  for (size_t i = 0; i < views.size(); ++i) halves[i % 2].push_back(static_cast<int>(i));
  const bool can_cross_validate = options.cross_validate &&
                                  static_cast<int>(halves[1].size()) >= kMinViewsPerHalf;
  if (options.cross_validate && !can_cross_validate)
    out.warnings.push_back("only " + std::to_string(views.size()) +
                           " usable images: too few to cross-validate (need " +
                           std::to_string(2 * kMinViewsPerHalf) + ")");
  const std::vector<Eigen::Vector2d> observed = ObservedPixels(views, width, height);
  const int total_solves =
      static_cast<int>(options.candidates.size()) * (can_cross_validate ? 3 : 1);
  int solves_started = 0;
  auto starting = [&](const std::string& what) {
    if (options.progress) options.progress(solves_started, total_solves, what);
    ++solves_started;
  };
  for (const std::string& short_name : options.candidates) {
    ModelTrial trial;
    trial.short_name = short_name;
    trial.lensmodel = MrcalLensModelName(short_name, seed, width, height);
    if (trial.lensmodel.empty())
      return Status::Error("--model: unknown lens model '" + short_name + "'");
    SolveOptions solve = options.solve;
    solve.lensmodel = trial.lensmodel;
    starting(short_name + ": all " + std::to_string(views.size()) + " images");
    trial.status = SolveIntrinsics(views, spec, width, height, seed, solve, &trial.fit);
    if (trial.status.ok() && spec.kind == BoardKind::kAprilGrid)
      trial.noise_inflation = TagNoiseInflation(TagCornerCorrelation(views, trial.fit));
    if (trial.status.ok() && can_cross_validate)
      CrossValidate(views, spec, width, height, seed, halves, solve, observed, starting, &trial);
    out.trials.push_back(std::move(trial));
  }
  // Supported first: a model whose halves disagree overfits, and its low sigma is no
  // yardstick for the others.
  for (ModelTrial& t : out.trials)
    if (t.status.ok())
      t.supported = t.cross_validation_px < 0 ? !can_cross_validate
                                              : t.cross_validation_px <= AgreementLimit_px(t);
  double best_sigma = std::numeric_limits<double>::infinity();
  int best = -1;
  for (int pass = 0; pass < 2 && best < 0; ++pass)
    for (size_t i = 0; i < out.trials.size(); ++i)
      if (out.trials[i].status.ok() && (pass == 1 || out.trials[i].supported) &&
          out.trials[i].fit.noise_sigma_px < best_sigma) {
        best_sigma = out.trials[i].fit.noise_sigma_px;
        best = static_cast<int>(i);
      }
  if (best < 0) return Status::Error("no lens model could be solved: " + out.trials[0].status.message());
  for (ModelTrial& t : out.trials)
    if (t.status.ok()) t.fits = t.fit.noise_sigma_px <= best_sigma * (1 + kFitTolerance);
  // A model whose sigma is higher still fits when it projects like the best model within what
  // the best model itself cannot pin down (its projection uncertainty where boards were seen):
  // the richer model's gain is then below its own noise.
  const ModelTrial& yardstick = out.trials[best];
  double uncertainty_sum = 0;
  int uncertainty_count = 0;
  for (const Eigen::Vector2d& pixel : observed) {
    const double u =
        ProjectionUncertainty_px(yardstick.fit, pixel, /*range_m=*/0,
                                 yardstick.fit.noise_sigma_px * yardstick.noise_inflation);
    if (u < 0 || !std::isfinite(u)) continue;
    uncertainty_sum += u * u;
    ++uncertainty_count;
  }
  const double best_uncertainty_px =
      uncertainty_count > 0 ? std::sqrt(uncertainty_sum / uncertainty_count) : -1;
  for (ModelTrial& t : out.trials) {
    if (!t.status.ok()) continue;
    t.best_uncertainty_px = best_uncertainty_px;
    t.projection_vs_best_px =
        ProjectionDifference_px(t.fit.lensmodel, t.fit.intrinsics, yardstick.fit.lensmodel,
                                yardstick.fit.intrinsics, observed);
    if (!std::isfinite(t.projection_vs_best_px)) t.projection_vs_best_px = -1;
    if (t.projection_vs_best_px >= 0 && t.projection_vs_best_px <= best_uncertainty_px)
      t.fits = true;
  }
  for (size_t i = 0; i < out.trials.size(); ++i)
    if (out.trials[i].fits && out.trials[i].supported) {
      out.chosen = static_cast<int>(i);
      break;
    }
  if (out.chosen < 0) {
    out.chosen = best;
    out.warnings.push_back("no model both fits and has halves that agree; kept the best fit, " +
                           out.trials[best].short_name + " (cross-validation " +
                           Fixed(out.trials[best].cross_validation_px, 3) +
                           " px): add images that cover the whole imager");
  }
  *choice = std::move(out);
  return Status::Ok();
}

}  // namespace fresco::calib
