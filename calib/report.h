// What `fresco calib solve` writes: the mrcal .cameramodel (any mrcal lens model, numbers at
// full precision, checked with mrcal's own reader before the file is replaced) and the
// report JSON beside it (docs/contract.md fields plus the evidence for the model choice).
#pragma once

#include <string>

#include "calib/calibrate.h"

namespace fresco::calib {

// The .cameramodel text (mrcal's Python-dict format) for a camera at the reference.
std::string CameraModelText(const std::string& lensmodel, const std::vector<double>& intrinsics,
                            int width, int height);

// CAMERA.cameramodel -> CAMERA.report.json (and .residuals.png etc. via `suffix`).
std::string SiblingPath(const std::string& cameramodel_path, const std::string& suffix);

// Writes the chosen model to `cameramodel_path` and the report beside it, atomically. The
// model carries mrcal's optimization_inputs (calib/optimization_inputs.h) when python3-mrcal
// can write them; otherwise it is written without them and `optimization_inputs_missing`
// (optional) gets the reason ("" when they were written). The report says which.
Status WriteCalibration(const std::string& cameramodel_path, const CalibrateRequest& request,
                        const CalibrationRun& run, const std::vector<std::string>& pictures,
                        std::string* optimization_inputs_missing = nullptr);

// Everything `fresco calib solve --out` writes (the CLI and the app share it): the folder,
// CAMERA.residuals.png, CAMERA.coverage.png and CAMERA.uncertainty.png (unless !pictures), the
// corners as mrcal's corners.vnl when `corners_vnl` is set, then the .cameramodel and the report.
struct CalibrationOutputs {
  bool pictures = true;
  std::string corners_vnl;  // "" = none
};
Status WriteCalibrationOutputs(const std::string& cameramodel_path, const CalibrateRequest& request,
                               const CalibrationRun& run, const CalibrationOutputs& outputs,
                               std::string* optimization_inputs_missing = nullptr);

// The report as JSON text.
std::string ReportJson(const CalibrateRequest& request, const CalibrationRun& run,
                       const std::vector<std::string>& pictures);

}  // namespace fresco::calib
