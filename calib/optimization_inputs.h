// The .cameramodel with mrcal's `optimization_inputs`: the solved problem (the corners with
// mrcal's outlier flags, the board poses, the board warp, the solver's selections), which
// mrcal's own tools need (mrcal-show-projection-uncertainty, mrcal-show-residuals,
// mrcal.projection_uncertainty, ...). mrcal stores them as a compressed numpy archive,
// base85-encoded; python3-mrcal writes that: the problem goes as JSON to Debian's
// /usr/bin/python3 (the python3 on PATH may be another one), where
// mrcal.cameramodel(optimization_inputs=..., icam_intrinsics=0) writes the model.
#pragma once

#include <string>

#include "calib/calibrate.h"

namespace fresco::calib {

inline constexpr char kSystemPython[] = "/usr/bin/python3";

// The chosen model's solved problem as JSON (what the Python side reads): lensmodel,
// intrinsics, imagersize, frames_rt_toref (board -> camera, one per view), calobject_warp
// (null when not solved), the board grid, observations [view, grid index, x, y, weight]
// (weight -1: rejected by mrcal's outlier rejection), the solver's do_* selections and the
// image paths.
std::string OptimizationInputsJson(const CalibrateRequest& request, const CalibrationRun& run);

// Writes the chosen model with its optimization_inputs to `path` with python3-mrcal. Error
// with the reason (no /usr/bin/python3, no python3-mrcal, or its message) otherwise: the
// caller then writes the model without them.
Status WriteCameraModelWithOptimizationInputs(const std::string& path,
                                              const CalibrateRequest& request,
                                              const CalibrationRun& run);

}  // namespace fresco::calib
