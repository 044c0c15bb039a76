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
                                half_fit[1].lensmodel, half_fit[1].intrinsics, observed, &compared,
                                &diffs))
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
    const double angle =
        std::acos(std::clamp(rays[0].normalized().dot(rays[1].normalized()), -1.0, 1.0));
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
  const int nx = static_cast<int>(std::ceil(width / cell)),
            ny = static_cast<int>(std::ceil(height / cell));
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

namespace {

// The calibration's data the models are fitted to.
struct FitInputs {
  const std::vector<BoardView>& views;
  const BoardSpec& spec;
  int width = 0, height = 0;
  const CalibrationSeed& seed;
};

// Chooses among the candidate lens models (FitLensModels): the state its steps share.
class ModelSelector {
 public:
  ModelSelector(const FitInputs& in, const SelectOptions& options)
      : in_(in), options_(options), observed_(ObservedPixels(in.views, in.width, in.height)) {
    for (size_t i = 0; i < in.views.size(); ++i) halves_[i % 2].push_back(static_cast<int>(i));
    can_cross_validate_ =
        options.cross_validate && static_cast<int>(halves_[1].size()) >= kMinViewsPerHalf;
    if (options.cross_validate && !can_cross_validate_)
      out_.warnings.push_back("only " + std::to_string(in.views.size()) +
                              " usable images: too few to cross-validate (need " +
                              std::to_string(2 * kMinViewsPerHalf) + ")");
    total_solves_ = static_cast<int>(options.candidates.size()) * (can_cross_validate_ ? 3 : 1);
  }

  // Every candidate solved on all images; an error when none could be.
  Status SolveCandidates() {
    for (const std::string& short_name : options_.candidates) {
      ModelTrial trial;
      trial.short_name = short_name;
      trial.lensmodel = MrcalLensModelName(short_name, in_.seed, in_.width, in_.height);
      if (trial.lensmodel.empty())
        return Status::Error("--model: unknown lens model '" + short_name + "'");
      SolveOptions solve = options_.solve;
      solve.lensmodel = trial.lensmodel;
      Starting(short_name + ": all " + std::to_string(in_.views.size()) + " images");
      trial.status =
          SolveIntrinsics(in_.views, in_.spec, in_.width, in_.height, in_.seed, solve, &trial.fit);
      if (trial.status.ok() && in_.spec.kind == BoardKind::kAprilGrid) {
        trial.corner_correlation = TagCornerCorrelation(in_.views, trial.fit);
        trial.noise_inflation = TagNoiseInflation(trial.corner_correlation);
      }
      out_.trials.push_back(std::move(trial));
    }
    if (std::none_of(out_.trials.begin(), out_.trials.end(),
                     [](const ModelTrial& t) { return t.status.ok(); }))
      return Status::Error("no lens model could be solved: " + out_.trials[0].status.message());
    return Status::Ok();
  }

  // The halves are solved only where the choice depends on them (splined's halves are most
  // of `auto`'s time on an AprilGrid): agree_[i] is -1 until model i's halves are compared.
  // Simple to rich: the first model that is supported and fits whichever the yardstick turns
  // out to be. Where that is open, the simplest (cheapest) model whose halves would settle it
  // is compared, and the search starts again.
  void Choose() {
    const int n = static_cast<int>(out_.trials.size());
    agree_.assign(n, can_cross_validate_ ? -1 : 1);
    for (int i = 0; i < n; ++i)
      if (!out_.trials[i].status.ok()) agree_[i] = 0;
    if (options_.all_halves)
      for (int i = 0; i < n; ++i)
        if (agree_[i] < 0) CompareHalves(i);
    for (int i = 0; i < n; ++i)
      if (out_.trials[i].status.ok()) by_sigma_.push_back(i);
    std::stable_sort(by_sigma_.begin(), by_sigma_.end(), [&](int a, int b) {
      return out_.trials[a].fit.noise_sigma_px < out_.trials[b].fit.noise_sigma_px;
    });
    while (out_.chosen < 0) {
      const std::vector<int> possible = PossibleYardsticks();
      if (possible.empty()) break;  // no model's halves agree
      const int settle = ChooseOrSettle(possible);
      if (out_.chosen >= 0 || settle < 0 || settle >= n) break;
      CompareHalves(settle);
    }
  }

  // Report every model against the yardstick: the lowest-sigma supported model (or, when no
  // model's halves agree, the lowest-sigma one).
  ModelChoice Report() {
    int best = -1;
    for (int i : by_sigma_)
      if (agree_[i] == 1) {
        best = i;
        break;
      }
    if (best < 0) best = by_sigma_.front();
    for (int i = 0; i < static_cast<int>(out_.trials.size()); ++i) {
      ModelTrial& t = out_.trials[i];
      if (!t.status.ok()) continue;
      t.supported = agree_[i] == 1;
      t.halves_skipped = agree_[i] < 0;
      t.fits = Fits(i, best);
      t.projection_vs_best_px = ProjectionDiff(i, best);
      t.best_uncertainty_px = Uncertainty(best);
    }
    if (out_.chosen < 0) {
      out_.chosen = best;
      out_.warnings.push_back("no model both fits and has halves that agree; kept the best fit, " +
                              out_.trials[best].short_name + " (cross-validation " +
                              Fixed(out_.trials[best].cross_validation_px, 3) +
                              " px): add images that cover the whole imager");
    }
    return std::move(out_);
  }

 private:
  void Starting(const std::string& what) {
    if (options_.progress) options_.progress(solves_started_, total_solves_, what);
    ++solves_started_;
  }

  void CompareHalves(int i) {
    ModelTrial& t = out_.trials[i];
    SolveOptions solve = options_.solve;
    solve.lensmodel = t.lensmodel;
    CrossValidate(
        in_.views, in_.spec, in_.width, in_.height, in_.seed, halves_, solve, observed_,
        [this](const std::string& what) { Starting(what); }, &t);
    agree_[i] = t.cross_validation_px >= 0 && t.cross_validation_px <= AgreementLimit_px(t);
  }

  // The yardstick is the supported model with the lowest sigma: any model not yet compared
  // below the lowest known-supported one may still be it.
  std::vector<int> PossibleYardsticks() const {
    std::vector<int> possible;
    for (int i : by_sigma_) {
      if (agree_[i] == 0) continue;
      possible.push_back(i);
      if (agree_[i] == 1) break;
    }
    return possible;
  }

  // Sets the choice when a supported model fits every possible yardstick; else returns the
  // simplest model whose halves would settle it (n: none to compare, -1: none fits).
  int ChooseOrSettle(const std::vector<int>& possible) {
    const int n = static_cast<int>(out_.trials.size());
    int settle = -1;
    for (int i = 0; i < n && out_.chosen < 0 && settle < 0; ++i) {
      if (agree_[i] == 0) continue;
      int fitting = 0;
      for (int y : possible) fitting += Fits(i, y);
      if (fitting == 0) continue;  // too simple whichever model is the yardstick
      if (fitting == static_cast<int>(possible.size()) && agree_[i] == 1) {
        out_.chosen = i;
        break;
      }
      settle = agree_[i] < 0 ? i : n;
      for (int y : possible)
        if (agree_[y] < 0) settle = std::min(settle, y);
    }
    return settle;
  }

  // Yardstick y's RMS projection uncertainty (computed once).
  double Uncertainty(int y) {
    auto it = uncertainty_of_.find(y);
    if (it == uncertainty_of_.end())
      it = uncertainty_of_.emplace(y, RmsProjectionUncertainty_px(out_.trials[y], observed_)).first;
    return it->second;
  }

  // Model i's projection difference from yardstick y (computed once; -1 where not finite).
  double ProjectionDiff(int i, int y) {
    auto it = diff_of_.find({i, y});
    if (it == diff_of_.end()) {
      const ModelTrial& a = out_.trials[i];
      const ModelTrial& b = out_.trials[y];
      double d = ProjectionDifference_px(a.fit.lensmodel, a.fit.intrinsics, b.fit.lensmodel,
                                         b.fit.intrinsics, observed_);
      it = diff_of_.emplace(std::make_pair(i, y), std::isfinite(d) ? d : -1).first;
    }
    return it->second;
  }

  // FITS against yardstick y: sigma within kFitTolerance of y's, or a projection within y's
  // own uncertainty of y's (the richer model's gain is then below its own noise).
  bool Fits(int i, int y) {
    if (out_.trials[i].fit.noise_sigma_px <=
        out_.trials[y].fit.noise_sigma_px * (1 + kFitTolerance))
      return true;
    const double d = ProjectionDiff(i, y);
    return d >= 0 && d <= Uncertainty(y);
  }

  const FitInputs in_;
  const SelectOptions& options_;
  const std::vector<Eigen::Vector2d> observed_;
  std::vector<int> halves_[2];
  bool can_cross_validate_ = false;
  int total_solves_ = 0, solves_started_ = 0;
  ModelChoice out_;
  std::vector<int> agree_;
  std::vector<int> by_sigma_;
  std::map<int, double> uncertainty_of_;           // yardstick -> RMS projection uncertainty
  std::map<std::pair<int, int>, double> diff_of_;  // (model, yardstick) -> projection diff
};

}  // namespace

Status FitLensModels(const std::vector<BoardView>& views, const BoardSpec& spec, int width,
                     int height, const CalibrationSeed& seed, const SelectOptions& options,
                     ModelChoice* choice) {
  ModelSelector selector(FitInputs{views, spec, width, height, seed}, options);
  FRESCO_RETURN_IF_ERROR(selector.SolveCandidates());
  selector.Choose();
  *choice = selector.Report();
  return Status::Ok();
}

}  // namespace fresco::calib
