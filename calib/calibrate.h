// `fresco calib solve` as a library call: read the images of a folder, detect the board in
// each (failures listed with their reason), seed, fit the lens model(s), estimate how
// correlated the corner noise is, and check the data for the classic traps (few images,
// part of the imager never observed, boards never tilted), as warnings.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "calib/model_select.h"

namespace fresco::calib {

struct CalibrateRequest {
  std::string images_dir;
  BoardSpec board;
  std::string model = "auto";  // auto or a short name (LensModelShortNames)
  DetectOptions detect;
  bool cross_validate = true;
};

struct RejectedImage {
  std::string name;
  std::string reason;
};

struct CalibrationRun {
  int width = 0, height = 0;
  std::vector<BoardView> views;  // images used, sorted by name
  std::vector<RejectedImage> rejected;
  CalibrationSeed seed;
  ModelChoice choice;
  std::vector<std::string> warnings;  // data traps and model-choice doubts, one line each
  // AprilGrid: correlation of the residuals of corners of one tag (same coordinate), and
  // the factor sqrt(1 + 3 rho) by which it inflates the uncertainties (1 for chessboards).
  double corner_correlation = 0;
  double noise_inflation = 1;
  double coverage_fraction = 0;  // imager cells (16 x 12) holding a corner
  double max_tilt_deg = 0;       // largest board tilt from fronto-parallel, over the views

  const ModelTrial& Chosen() const { return choice.trials[choice.chosen]; }
};

// Images: *.png *.jpg *.jpeg *.bmp *.tif *.tiff in `dir` (not recursive), by name.
Status ListImages(const std::string& dir, std::vector<std::string>* paths);

// Detects the board in every image. Fails (bad input) when the folder has no image or fewer
// than kMinViews images with a board.
Status DetectViews(const CalibrateRequest& request, CalibrationRun* run);

// Everything after detection.
Status SolveViews(const CalibrateRequest& request, CalibrationRun* run);

constexpr int kMinViews = 3;
constexpr int kFewViews = 10;

}  // namespace fresco::calib
