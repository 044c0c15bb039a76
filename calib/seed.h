// Seeds for the mrcal solve, with no hand-tuned guesses: OpenCV's calibrateCamera on the
// planar board (Zhang's homography initialisation, then Levenberg-Marquardt) with a
// two-term radial model, whose core (fx, fy, cx, cy), k1, k2 and per-view board poses seed
// mrcal. Views with fewer than 4 corners cannot be seeded and are refused by the caller.
#pragma once

#include <array>
#include <functional>
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

// With `cancelled` set, OpenCV's calibration (seconds on many views, with no way to stop it)
// runs in a child process that a Cancel abandons (abandonable.h): the seed is then, to the
// bit, the one made in this process, or the call fails with "cancelled".
Status SeedCalibration(const std::vector<BoardView>& views, const BoardSpec& spec, int width,
                       int height, CalibrationSeed* seed,
                       const std::function<bool()>& cancelled = nullptr);

}  // namespace fresco::calib
