// Lens-model fitting by short name and `--model auto`: fit pinhole, opencv4, opencv5,
// opencv8 and splined (simple to rich) and keep the simplest model the data supports.
//
// A model FITS when its noise estimate sigma = sqrt(SSR / (2 N_inliers - N_state)) (mrcal's
// residuals, degrees of freedom removed) is within kFitTolerance of the lowest sigma of all
// models: a model too simple for the lens leaves systematic residuals and a larger sigma.
// A model is SUPPORTED when cross-validation agrees: the views are split into two halves
// (even/odd images), each half is solved alone, and the two solutions' projections over the
// observed part of the imager differ by at most max(3 sigma, 0.3 px) RMS (after the best
// small rotation, as in mrcal's projection diff). The "best" sigma that FITS compares with is
// the lowest among the supported models (an overfitting model's low sigma is no yardstick).
// `auto` keeps the simplest model that fits and is supported; if none is, the best-fitting
// one, with a warning.
#pragma once

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
  bool fits = false;
  bool supported = false;
};

struct ModelChoice {
  std::vector<ModelTrial> trials;
  int chosen = -1;                    // index into trials
  std::vector<std::string> warnings;
};

struct SelectOptions {
  std::vector<std::string> candidates = LensModelShortNames();
  SolveOptions solve;                 // lensmodel is set per candidate
  bool cross_validate = true;
};

constexpr double kFitTolerance = 0.03;  // sigma may exceed the best by 3 %

Status FitLensModels(const std::vector<BoardView>& views, const BoardSpec& spec, int width,
                     int height, const CalibrationSeed& seed, const SelectOptions& options,
                     ModelChoice* choice);

// Pixels on a grid over the imager where the views have observations (cells of ~1/16 of the
// width holding a corner): where cross-validation compares models.
std::vector<Eigen::Vector2d> ObservedPixels(const std::vector<BoardView>& views, int width,
                                            int height);

}  // namespace fresco::calib
