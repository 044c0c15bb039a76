// Seeds for the mrcal solve, with no hand-tuned guesses: OpenCV's calibrateCamera on the
// planar board (Zhang's homography initialisation, then Levenberg-Marquardt) with a
// two-term radial model, whose core (fx, fy, cx, cy), k1, k2 and per-view board poses seed
// mrcal. Views with fewer than 4 corners cannot be seeded and are refused by the caller.
#pragma once

#include <array>
#include <vector>

#include "calib/board.h"
#include "calib/observations.h"
#include "pipeline/core/status.h"

namespace fresco::calib {

struct CalibrationSeed {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double k1 = 0, k2 = 0;
  std::vector<std::array<double, 6>> rt_cam_from_board;  // per view: Rodrigues r, then t (m)
  double rms_px = 0;                                     // OpenCV's reprojection RMS
};

Status SeedCalibration(const std::vector<BoardView>& views, const BoardSpec& spec, int width,
                       int height, CalibrationSeed* seed);

}  // namespace fresco::calib
