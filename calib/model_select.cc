#include "calib/model_select.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <utility>

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

// RMS over `pixels` of the trial's projection uncertainty at infinity (corner noise times its
// inflation); -1 when it cannot be computed anywhere.
double RmsProjectionUncertainty_px(const ModelTrial& trial,
                                   const std::vector<Eigen::Vector2d>& pixels) {
  double sum = 0;
  int count = 0;
  for (const Eigen::Vector2d& pixel : pixels) {
    const double u = ProjectionUncertainty_px(trial.fit, pixel, /*range_m=*/0,
                                              trial.fit.noise_sigma_px * trial.noise_inflation);
    if (u < 0 || !std::isfinite(u)) continue;
    sum += u * u;
    ++count;
  }
  return count > 0 ? std::sqrt(sum / count) : -1;
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

std::string CrossValidationText(const ModelTrial& trial) {
  if (trial.halves_skipped) return "halves not compared (not needed)";
  if (trial.cross_validation_px < 0) return "halves not compared";
  return "halves differ " + Fixed(trial.cross_validation_px, 4) + " px (limit " +
         Fixed(AgreementLimit_px(trial), 4) + ")";
}

std::string VerdictText(const ModelTrial& trial) {
  if (!trial.status.ok()) return "failed";
  std::string text = trial.fits ? "fits" : "does not fit";
  if (!trial.supported && !trial.halves_skipped) text += ", halves disagree";
  return text;
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
    if (trial.status.ok() && spec.kind == BoardKind::kAprilGrid) {
      trial.corner_correlation = TagCornerCorrelation(views, trial.fit);
      trial.noise_inflation = TagNoiseInflation(trial.corner_correlation);
    }
    out.trials.push_back(std::move(trial));
  }
  if (std::none_of(out.trials.begin(), out.trials.end(),
                   [](const ModelTrial& t) { return t.status.ok(); }))
    return Status::Error("no lens model could be solved: " + out.trials[0].status.message());

  // The halves are solved only where the choice depends on them (splined's halves are most
  // of `auto`'s time on an AprilGrid): agree[i] is -1 until model i's halves are compared.
  const int n = static_cast<int>(out.trials.size());
  std::vector<int> agree(n, can_cross_validate ? -1 : 1);
  for (int i = 0; i < n; ++i)
    if (!out.trials[i].status.ok()) agree[i] = 0;
  auto compare_halves = [&](int i) {
    ModelTrial& t = out.trials[i];
    SolveOptions solve = options.solve;
    solve.lensmodel = t.lensmodel;
    CrossValidate(views, spec, width, height, seed, halves, solve, observed, starting, &t);
    agree[i] = t.cross_validation_px >= 0 && t.cross_validation_px <= AgreementLimit_px(t);
  };
  if (options.all_halves)
    for (int i = 0; i < n; ++i)
      if (agree[i] < 0) compare_halves(i);
  std::vector<int> by_sigma;
  for (int i = 0; i < n; ++i)
    if (out.trials[i].status.ok()) by_sigma.push_back(i);
  std::stable_sort(by_sigma.begin(), by_sigma.end(), [&](int a, int b) {
    return out.trials[a].fit.noise_sigma_px < out.trials[b].fit.noise_sigma_px;
  });
  // The yardstick is the supported model with the lowest sigma: any model not yet compared
  // below the lowest known-supported one may still be it.
  auto possible_yardsticks = [&] {
    std::vector<int> possible;
    for (int i : by_sigma) {
      if (agree[i] == 0) continue;
      possible.push_back(i);
      if (agree[i] == 1) break;
    }
    return possible;
  };
  std::map<int, double> uncertainty_of;             // yardstick -> RMS projection uncertainty
  std::map<std::pair<int, int>, double> diff_of;    // (model, yardstick) -> projection diff
  auto uncertainty = [&](int y) {
    auto it = uncertainty_of.find(y);
    if (it == uncertainty_of.end())
      it = uncertainty_of.emplace(y, RmsProjectionUncertainty_px(out.trials[y], observed)).first;
    return it->second;
  };
  auto projection_diff = [&](int i, int y) {
    auto it = diff_of.find({i, y});
    if (it == diff_of.end()) {
      double d = ProjectionDifference_px(out.trials[i].fit.lensmodel, out.trials[i].fit.intrinsics,
                                         out.trials[y].fit.lensmodel, out.trials[y].fit.intrinsics,
                                         observed);
      it = diff_of.emplace(std::make_pair(i, y), std::isfinite(d) ? d : -1).first;
    }
    return it->second;
  };
  // FITS against yardstick y: sigma within kFitTolerance of y's, or a projection within y's
  // own uncertainty of y's (the richer model's gain is then below its own noise).
  auto fits = [&](int i, int y) {
    if (out.trials[i].fit.noise_sigma_px <= out.trials[y].fit.noise_sigma_px * (1 + kFitTolerance))
      return true;
    const double d = projection_diff(i, y);
    return d >= 0 && d <= uncertainty(y);
  };
  // Simple to rich: the first model that is supported and fits whichever the yardstick turns
  // out to be. Where that is open, the simplest (cheapest) model whose halves would settle it
  // is compared, and the search starts again.
  while (out.chosen < 0) {
    const std::vector<int> possible = possible_yardsticks();
    if (possible.empty()) break;  // no model's halves agree
    int settle = -1;
    for (int i = 0; i < n && out.chosen < 0 && settle < 0; ++i) {
      if (agree[i] == 0) continue;
      int fitting = 0;
      for (int y : possible) fitting += fits(i, y);
      if (fitting == 0) continue;  // too simple whichever model is the yardstick
      if (fitting == static_cast<int>(possible.size()) && agree[i] == 1) {
        out.chosen = i;
        break;
      }
      settle = agree[i] < 0 ? i : n;
      for (int y : possible)
        if (agree[y] < 0) settle = std::min(settle, y);
    }
    if (out.chosen >= 0 || settle < 0 || settle >= n) break;
    compare_halves(settle);
  }
  // Report every model against the yardstick: the lowest-sigma supported model (or, when no
  // model's halves agree, the lowest-sigma one).
  int best = -1;
  for (int i : by_sigma)
    if (agree[i] == 1) {
      best = i;
      break;
    }
  if (best < 0) best = by_sigma.front();
  for (int i = 0; i < n; ++i) {
    ModelTrial& t = out.trials[i];
    if (!t.status.ok()) continue;
    t.supported = agree[i] == 1;
    t.halves_skipped = agree[i] < 0;
    t.fits = fits(i, best);
    t.projection_vs_best_px = projection_diff(i, best);
    t.best_uncertainty_px = uncertainty(best);
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
