// Lens-model fitting by short name and `--model auto`: fit pinhole, opencv4, opencv5,
// opencv8 and splined (simple to rich) and keep the simplest model the data supports.
//
// A model FITS when its noise estimate sigma = sqrt(SSR / (2 N_inliers - N_state)) (mrcal's
// residuals, degrees of freedom removed) is within kFitTolerance of the lowest sigma of all
// models: a model too simple for the lens leaves systematic residuals and a larger sigma.
// A model is SUPPORTED when cross-validation agrees: the views are split into two halves
// (even/odd images), each half is solved alone, and the two solutions' projections over the
// observed part of the imager (after the best small rotation, as in mrcal's projection diff)
// differ by at most kAgreeFactor times what the halves' own projection uncertainty predicts
// for two independent solves, sqrt(u0^2 + u1^2) RMS over the same pixels (at infinity, like
// the diff), and never less than kAgreeFloorPx. The corner noise behind that uncertainty is
// the half's sigma times the AprilTag design effect (calib/noise_correlation.h): AprilTag
// corner errors are correlated, so a rule on sigma alone is too strict on real AprilGrids.
// A model that misses part of the lens leaves systematic differences beyond its
// uncertainty; a model richer than the data has large uncertainty, and FITS (above) keeps
// the simplest. The "best" model that FITS compares with is the one with the lowest sigma
// among the supported models (an overfitting model's low sigma is no yardstick). A model
// with a higher sigma still FITS when its projection is within the best model's own
// projection uncertainty of the best's (RMS over the observed imager, at infinity): the
// richer model's gain is below what it can pin down itself.
// `auto` keeps the simplest model that fits and is supported; if none is, the best-fitting
// one, with a warning.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "calib/mrcal_solve.h"

namespace fresco::calib {

// Short names in order of richness.
const std::vector<std::string>& LensModelShortNames();  // pinhole ... splined
// The full mrcal name for a short name; the splined configuration (Nx, Ny, fov_x_deg) is
// sized from the seed and the imager. "" for an unknown short name.
std::string MrcalLensModelName(const std::string& short_name, const CalibrationSeed& seed,
                               int width, int height);

struct ModelTrial {
  std::string short_name;
  std::string lensmodel;              // full mrcal name
  Status status;                      // failed solves are reported, not fatal
  SolveResult fit;                    // on all views
  double cross_validation_px = -1;    // RMS diff of the half solves (-1: not computed)
  // RMS of sqrt(u0^2 + u1^2) over the compared pixels: the diff the halves' own uncertainty
  // predicts (-1: not computed; the limit then falls back to 3 sigma x inflation).
  double cross_validation_expected_px = -1;
  double corner_correlation = 0;      // AprilGrid: rho of this model's tag-corner residuals
  double noise_inflation = 1;         // AprilGrid: sqrt(1 + 3 rho)
  // RMS projection difference to the best model (lowest sigma among the supported) over the
  // observed pixels, and that model's RMS projection uncertainty there (-1: not computed).
  double projection_vs_best_px = -1;
  double best_uncertainty_px = -1;
  // The halves were not solved: the choice did not depend on them (cross_validation_px -1).
  bool halves_skipped = false;
  bool fits = false;
  bool supported = false;
};

struct ModelChoice {
  std::vector<ModelTrial> trials;
  int chosen = -1;                    // index into trials
  std::vector<std::string> warnings;
};

// Called before each solve: `done` of `total` solves finished, `what` the one starting.
using SolveProgress = std::function<void(int done, int total, const std::string& what)>;

struct SelectOptions {
  std::vector<std::string> candidates = LensModelShortNames();
  SolveOptions solve;                 // lensmodel is set per candidate
  bool cross_validate = true;
  SolveProgress progress;             // optional
  // Solve every model's halves even where the choice does not depend on them (the choice is
  // the same; the report then has every model's cross-validation).
  bool all_halves = false;
};

constexpr double kFitTolerance = 0.03;  // sigma may exceed the best by 3 %
constexpr double kAgreeFactor = 3.0;    // halves may differ 3x their predicted difference
constexpr double kAgreeFloorPx = 0.3;   // differences this small always agree

// The largest cross_validation_px with which `trial` is supported.
double AgreementLimit_px(const ModelTrial& trial);
// For people: "halves differ 0.0908 px (limit 0.8254)", "halves not compared (not needed)"
// or "halves not compared"; and "fits", "does not fit, halves disagree", ...
std::string CrossValidationText(const ModelTrial& trial);
std::string VerdictText(const ModelTrial& trial);

Status FitLensModels(const std::vector<BoardView>& views, const BoardSpec& spec, int width,
                     int height, const CalibrationSeed& seed, const SelectOptions& options,
                     ModelChoice* choice);

// Pixels on a grid over the imager where the views have observations (cells of ~1/16 of the
// width holding a corner): where cross-validation compares models.
std::vector<Eigen::Vector2d> ObservedPixels(const std::vector<BoardView>& views, int width,
                                            int height);

}  // namespace fresco::calib
