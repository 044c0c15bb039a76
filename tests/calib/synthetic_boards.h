// Synthetic calibration data for the calib tests: board corners seen through a known camera
// (mrcal's projection of the true lens model) from board poses that tilt and sweep the imager
// (or stay at its centre, or on one side of it), with Gaussian corner noise; and a solve of
// such views through calib::SolveViews.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "calib/calibrate.h"

namespace fresco::calib::testing {

enum class Placement {
  kSweep,     // boards tilted +-35 deg, centres on an ellipse over the imager
  kCentre,    // boards near fronto-parallel, at the imager's centre
  kLeftSide,  // boards tilted like kSweep, all on the imager's left side
};

struct SyntheticCapture {
  std::string lensmodel = "LENSMODEL_PINHOLE";
  std::vector<double> intrinsics = {600, 605, 322, 238};
  int width = 640, height = 480;
  int views = 14;
  double noise_px = 0.2;
  // AprilGrid: one shift per tag shared by its 4 corners (the correlated part of AprilTag
  // corner noise), added to the independent noise_px; corner-to-corner correlation is
  // tag_shift^2 / (tag_shift^2 + noise^2).
  double tag_shift_px = 0;
  Placement placement = Placement::kSweep;
  double distance_m = 0.42;  // mean distance of the board's centre
  unsigned seed = 7;
};

// cam_from_board (Rodrigues r, then t) for view v.
std::array<double, 6> SyntheticPose(int v, const BoardSpec& spec, const SyntheticCapture& capture);
// Corners inside the imager, with noise.
std::vector<BoardView> SyntheticViews(const BoardSpec& spec, const SyntheticCapture& capture);
// SolveViews on `views` (EXPECTs success).
CalibrationRun SolveSynthetic(const std::vector<BoardView>& views, const BoardSpec& spec, int width,
                              int height, const std::string& model, bool cross_validate = true);
BoardSpec Spec(const std::string& text);
// All warnings, one per line.
std::string AllWarnings(const CalibrationRun& run);

}  // namespace fresco::calib::testing
