#include "calib/optimization_inputs.h"

#include <filesystem>
#include <sstream>

#include <nlohmann/json.hpp>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/run_process.h"

namespace fresco::calib {
namespace {

// argv: the JSON of OptimizationInputsJson, the .cameramodel to write. The observations go
// into mrcal's (Nviews, H, W, 3) board pool (x, y, weight; weight -1 where nothing was seen
// and where mrcal rejected the corner), as mrcal.optimize() left it after our solve.
const char kScript[] = R"(
import json, sys
import numpy as np
import mrcal
d = json.load(open(sys.argv[1]))
W, H = d['grid_width_n'], d['grid_height_n']
N = len(d['frames_rt_toref'])
pool = np.zeros((N, H, W, 3))
pool[..., 2] = -1.0
for view, index, x, y, weight in d['observations']:
    pool[view, index // W, index % W] = (x, y, weight)
warp = d['calobject_warp']
inputs = dict(
    intrinsics=np.array([d['intrinsics']], dtype=float),
    extrinsics_rt_fromref=np.zeros((0, 6), dtype=float),
    frames_rt_toref=np.array(d['frames_rt_toref'], dtype=float),
    points=None,
    observations_board=pool,
    indices_frame_camintrinsics_camextrinsics=np.array([[i, 0, -1] for i in range(N)],
                                                       dtype=np.int32),
    observations_point=None,
    indices_point_camintrinsics_camextrinsics=None,
    lensmodel=d['lensmodel'],
    imagersizes=np.array([d['imagersize']], dtype=np.int32),
    calobject_warp=None if warp is None else np.array(warp, dtype=float),
    do_optimize_intrinsics_core=d['do_optimize_intrinsics_core'],
    do_optimize_intrinsics_distortions=d['do_optimize_intrinsics_distortions'],
    do_optimize_extrinsics=True,  # no extrinsics (one camera, at the reference); mrcal-calibrate-cameras sets it too
    do_optimize_frames=True,
    do_optimize_calobject_warp=warp is not None,
    calibration_object_spacing=d['calibration_object_spacing'],
    do_apply_outlier_rejection=d['do_apply_outlier_rejection'],
    do_apply_regularization=True,
    verbose=False,
    imagepaths=np.array(d['imagepaths']))
model = mrcal.cameramodel(optimization_inputs=inputs, icam_intrinsics=0)
model.write(sys.argv[2], note=d['note'])
)";

// The last non-empty line of Python's output (its error message).
std::string LastLine(const std::string& text) {
  std::istringstream lines(text);
  std::string line, last;
  while (std::getline(lines, line))
    if (!line.empty()) last = line;
  return last;
}

}  // namespace

std::string OptimizationInputsJson(const CalibrateRequest& request, const CalibrationRun& run) {
  const SolveResult& fit = run.Chosen().fit;
  const BoardGrid grid = MakeBoardGrid(request.board);
  nlohmann::json j;
  j["lensmodel"] = fit.lensmodel;
  j["intrinsics"] = fit.intrinsics;
  j["imagersize"] = {run.width, run.height};
  nlohmann::json frames = nlohmann::json::array(), observations = nlohmann::json::array(),
                 paths = nlohmann::json::array();
  for (size_t v = 0; v < run.views.size(); ++v) {
    frames.push_back(fit.views[v].rt_cam_from_board);
    paths.push_back((std::filesystem::path(request.images_dir) / run.views[v].name).string());
    const auto& corners = run.views[v].corners;
    for (size_t k = 0; k < corners.size(); ++k)
      observations.push_back({v, grid.grid_index_of_corner[corners[k].id], corners[k].pixel.x(),
                              corners[k].pixel.y(), fit.views[v].outlier[k] ? -1.0 : 1.0});
  }
  j["frames_rt_toref"] = frames;
  j["calobject_warp"] = fit.board_warp_solved ? nlohmann::json(fit.board_warp_m) : nlohmann::json();
  j["grid_width_n"] = grid.width_n;
  j["grid_height_n"] = grid.height_n;
  j["calibration_object_spacing"] = grid.spacing_m;
  j["observations"] = observations;
  j["do_optimize_intrinsics_core"] = true;
  j["do_optimize_intrinsics_distortions"] = fit.intrinsics.size() > 4;
  j["do_apply_outlier_rejection"] = fit.outlier_rejection;
  j["imagepaths"] = paths;
  j["note"] = "Written by Fresco (fresco calib solve, board " + request.board.text +
              "): optimization_inputs are the solved problem";
  return j.dump();
}

Status WriteCameraModelWithOptimizationInputs(const std::string& path,
                                              const CalibrateRequest& request,
                                              const CalibrationRun& run) {
  if (FindProgram(kSystemPython).empty())
    return Status::Error(std::string(kSystemPython) + " is missing");
  const std::string inputs_path = path + ".inputs.json", log_path = path + ".python.log";
  FRESCO_RETURN_IF_ERROR(WriteFileAtomic(inputs_path, OptimizationInputsJson(request, run)));
  std::error_code ec;
  std::filesystem::remove(log_path, ec);
  int exit_code = -1;
  Status status =
      RunProcess({kSystemPython, "-c", kScript, inputs_path, path}, log_path, &exit_code);
  std::string log;
  ReadFileToString(log_path, &log);
  std::filesystem::remove(inputs_path, ec);
  std::filesystem::remove(log_path, ec);
  if (!status.ok()) return status;
  if (exit_code != 0) {
    if (log.find("No module named 'mrcal'") != std::string::npos)
      return Status::Error("python3-mrcal is not installed (" + std::string(kSystemPython) + ")");
    return Status::Error(std::string(kSystemPython) +
                         " with python3-mrcal failed: " + LastLine(log));
  }
  return Status::Ok();
}

}  // namespace fresco::calib
