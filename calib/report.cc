#include "calib/report.h"

#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "calib/camera_consistency.h"
#include "calib/corners_vnl.h"
#include "calib/optimization_inputs.h"
#include "calib/pictures.h"
#include "pipeline/core/atomic_file.h"
#include "pipeline/core/image_io.h"

extern "C" {
#include <mrcal/mrcal.h>
}

namespace fresco::calib {
namespace {

std::string Number(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  return buffer;
}

nlohmann::json TrialJson(const ModelTrial& t) {
  nlohmann::json j;
  j["model"] = t.short_name;
  j["lensmodel"] = t.lensmodel;
  j["ok"] = t.status.ok();
  if (!t.status.ok()) {
    j["error"] = t.status.message();
    return j;
  }
  j["num_intrinsics"] = t.fit.intrinsics.size();
  j["num_states"] = t.fit.num_states;
  j["rms_px"] = t.fit.rms_px;
  j["noise_sigma_px"] = t.fit.noise_sigma_px;
  j["outliers"] = t.fit.outliers;
  j["cross_validation_px"] = t.cross_validation_px;
  j["cross_validation_expected_px"] = t.cross_validation_expected_px;
  j["cross_validation_limit_px"] = AgreementLimit_px(t);
  j["halves_skipped"] = t.halves_skipped;
  j["noise_inflation"] = t.noise_inflation;
  j["projection_vs_best_px"] = t.projection_vs_best_px;
  j["best_uncertainty_px"] = t.best_uncertainty_px;
  j["fits"] = t.fits;
  j["supported"] = t.supported;
  if (t.fit.intrinsics.size() <= 16) {
    j["intrinsics"] = t.fit.intrinsics;
    j["intrinsics_stdev"] = t.fit.intrinsics_stdev;
  } else {  // splined: the core only
    j["intrinsics_core"] =
        std::vector<double>(t.fit.intrinsics.begin(), t.fit.intrinsics.begin() + 4);
    if (t.fit.intrinsics_stdev.size() >= 4)
      j["intrinsics_core_stdev"] =
          std::vector<double>(t.fit.intrinsics_stdev.begin(), t.fit.intrinsics_stdev.begin() + 4);
  }
  return j;
}

nlohmann::json UncertaintyFiguresJson(const UncertaintyMap& u) {
  return {{"range_m", u.range_m},
          {"centre_px", u.centre_px},
          {"corners_px", {u.corners_px[0], u.corners_px[1], u.corners_px[2], u.corners_px[3]}},
          {"max_px", u.max_px},
          {"median_observed_px", u.median_observed_px}};
}

nlohmann::json UncertaintyJson(const CalibrationRun& run) {
  const UncertaintyMap& u = run.uncertainty;
  nlohmann::json j = UncertaintyFiguresJson(u);
  j["method"] =
      "mrcal's projection uncertainty (python3-mrcal 2.2 projection_uncertainty, 'mean frames'), "
      "on this solve's state covariance sigma^2 inv(JtJ) Jobs^T Jobs inv(JtJ): worst-direction "
      "1-sigma of the projection of the point seen at each pixel at range_m";
  j["sigma_px"] = u.sigma_px;
  j["corners_order"] = "top-left, top-right, bottom-left, bottom-right cells";
  j["grid_cols"] = u.cols;
  j["grid_rows"] = u.rows;
  j["stdev_px"] = u.stdev_px;  // (grid_rows, grid_cols) row-major, at cell centres
  nlohmann::json inf = UncertaintyFiguresJson(run.uncertainty_at_infinity);
  inf.erase("range_m");
  j["at_infinity"] = inf;
  return j;
}

}  // namespace

std::string CameraModelText(const std::string& lensmodel, const std::vector<double>& intrinsics,
                            int width, int height) {
  std::string text = "# Written by Fresco (fresco calib solve): an mrcal camera model.\n{\n";
  text += "    'lensmodel':  '" + lensmodel + "',\n\n";
  text += "    # intrinsics are fx,fy,cx,cy,distortion0,distortion1,....\n";
  text += "    'intrinsics': [";
  for (size_t i = 0; i < intrinsics.size(); ++i) text += (i ? ", " : " ") + Number(intrinsics[i]);
  text += " ],\n\n    # extrinsics are rt_fromref\n";
  text += "    'extrinsics': [ 0, 0, 0, 0, 0, 0 ],\n\n";
  text +=
      "    'imagersize': [ " + std::to_string(width) + ", " + std::to_string(height) + " ],\n}\n";
  return text;
}

std::string SiblingPath(const std::string& cameramodel_path, const std::string& suffix) {
  std::filesystem::path path(cameramodel_path);
  return (path.parent_path() / (path.stem().string() + suffix)).string();
}

std::string ReportJson(const CalibrateRequest& request, const CalibrationRun& run,
                       const std::vector<std::string>& pictures) {
  const ModelTrial& chosen = run.Chosen();
  const SolveResult& fit = chosen.fit;
  nlohmann::json j;
  j["lensmodel"] = chosen.lensmodel;
  j["model"] = chosen.short_name;
  j["model_requested"] = request.model;
  j["intrinsics"] = fit.intrinsics;
  j["intrinsics_stdev"] = fit.intrinsics_stdev;
  j["imagersize"] = {run.width, run.height};
  j["rms_px"] = fit.rms_px;
  j["noise_sigma_px"] = fit.noise_sigma_px;
  j["corners_used"] = fit.corners_used;
  j["corners_rejected_as_outliers"] = fit.outliers;
  j["board"] = request.board.text;
  j["board_warp_m"] = fit.board_warp_m;
  nlohmann::json used = nlohmann::json::array(), per_image = nlohmann::json::array();
  for (size_t v = 0; v < run.views.size(); ++v) {
    used.push_back(run.views[v].name);
    per_image.push_back({{"image", run.views[v].name},
                         {"corners", run.views[v].corners.size()},
                         {"outliers", fit.views[v].outliers},
                         {"rms_px", fit.views[v].rms_px},
                         {"rt_cam_from_board", fit.views[v].rt_cam_from_board}});
  }
  j["images_used"] = used;
  nlohmann::json rejected = nlohmann::json::array();
  for (const RejectedImage& r : run.rejected)
    rejected.push_back({{"image", r.name}, {"reason", r.reason}});
  j["images_rejected"] = rejected;
  // Per image: tags each detector read, tags kept, and the detection's wall time.
  nlohmann::json detections = nlohmann::json::array();
  double detect_ms = 0;
  for (const ViewDetection& d : run.detections) {
    detections.push_back({{"image", d.name},
                          {"used", d.used},
                          {"tags_apriltag", d.tags_library},
                          {"tags_aruco", d.tags_aruco},
                          {"tags_second_look", d.tags_second_look},
                          {"tags_kept", d.tags},
                          {"corners", d.corners},
                          {"detect_ms", d.detect_ms}});
    if (!d.used) detections.back()["reason"] = d.reason;
    detect_ms += d.detect_ms;
  }
  j["detections"] = detections;
  j["detect_ms_total"] = detect_ms;
  j["images_excluded"] = run.excluded;  // by name or glob (--exclude, the app's checkboxes)
  nlohmann::json splits = nlohmann::json::array();
  for (const SplitTest& t : run.split_tests)
    splits.push_back({{"split", t.how},
                      {"group_a", t.group_a},
                      {"group_b", t.group_b},
                      {"joint_sigma_px", t.joint_sigma_px},
                      {"split_sigma_px", t.split_sigma_px},
                      {"ratio", t.ratio}});
  j["one_camera"] = {
      {"image_sizes", run.image_sizes},
      {"split_tests", splits},
      {"ratio_limit", kSplitSigmaRatio},
      {"doubts", run.camera_doubts},
      {"method",
       "each split's two groups solved apart with the chosen model: a joint corner noise sigma "
       "over ratio_limit times the pooled sigma of the separate fits says two cameras"}};
  j["per_image"] = per_image;
  nlohmann::json tried = nlohmann::json::array();
  for (const ModelTrial& t : run.choice.trials) tried.push_back(TrialJson(t));
  j["models_tried"] = tried;
  j["model_selection"] =
      "simplest model that fits (noise sigma within 3 % of the best model's, or projection "
      "within the best model's own projection uncertainty of the best's: projection_vs_best_px "
      "<= best_uncertainty_px) and whose two "
      "half-data solves agree: cross_validation_px <= max(3 x cross_validation_expected_px, "
      "0.3 px), the expected difference being sqrt(u0^2 + u1^2) RMS from the halves' own "
      "projection uncertainty at infinity (corner noise x the AprilTag inflation); halves are "
      "solved only where the choice depends on them (halves_skipped: it did not)";
  j["seed"] = {{"method", "OpenCV calibrateCamera, k1 k2 only"},
               {"fx", run.seed.fx},
               {"fy", run.seed.fy},
               {"cx", run.seed.cx},
               {"cy", run.seed.cy},
               {"k1", run.seed.k1},
               {"k2", run.seed.k2},
               {"rms_px", run.seed.rms_px}};
  j["corner_noise"] = {
      {"tag_corner_correlation", run.corner_correlation},
      {"uncertainty_inflation", run.noise_inflation},
      {"method", request.board.kind == BoardKind::kAprilGrid
                     ? "AprilTag corners of one tag come from one quad fit: the correlation of "
                       "their residuals rho is measured and every intrinsics_stdev is "
                       "multiplied by sqrt(1 + 3 rho) (the design effect of 4 correlated corners)"
                     : "chessboard corners are found independently: no inflation"}};
  j["projection_uncertainty"] = UncertaintyJson(run);
  j["coverage_fraction"] = run.coverage_fraction;
  j["max_board_tilt_deg"] = run.max_tilt_deg;
  j["warnings"] = run.warnings;
  j["pictures"] = pictures;
  return j.dump(2) + "\n";
}

Status WriteCalibration(const std::string& cameramodel_path, const CalibrateRequest& request,
                        const CalibrationRun& run, const std::vector<std::string>& pictures,
                        std::string* optimization_inputs_missing) {
  const ModelTrial& chosen = run.Chosen();
  std::string missing;  // why the model has no optimization_inputs
  FRESCO_RETURN_IF_ERROR(WriteFileAtomicWith(cameramodel_path, [&](const std::string& temp) {
    std::string text;
    Status with_inputs = WriteCameraModelWithOptimizationInputs(temp, request, run);
    if (with_inputs.ok()) with_inputs = ReadFileToString(temp, &text);
    if (!with_inputs.ok()) {
      missing = with_inputs.message();
      text = CameraModelText(chosen.lensmodel, chosen.fit.intrinsics, run.width, run.height);
    }
    mrcal_cameramodel_t* check =
        mrcal_read_cameramodel_string(text.c_str(), static_cast<int>(text.size()));
    if (!check)
      return Status::Internal(cameramodel_path +
                              ": internal error: mrcal cannot read the model to write");
    mrcal_free_cameramodel(&check);
    return with_inputs.ok() ? Status::Ok() : WriteFileAtomic(temp, text);
  }));
  if (optimization_inputs_missing) *optimization_inputs_missing = missing;
  nlohmann::json report = nlohmann::json::parse(ReportJson(request, run, pictures));
  report["optimization_inputs"] =
      missing.empty() ? "written (python3-mrcal)" : "not written: " + missing;
  return WriteFileAtomic(SiblingPath(cameramodel_path, ".report.json"), report.dump(2) + "\n");
}

Status WriteCalibrationOutputs(const std::string& cameramodel_path, const CalibrateRequest& request,
                               const CalibrationRun& run, const CalibrationOutputs& outputs,
                               std::string* optimization_inputs_missing) {
  const std::filesystem::path parent = std::filesystem::path(cameramodel_path).parent_path();
  if (!parent.empty()) FRESCO_RETURN_IF_ERROR(MakeDirectories(parent.string()));
  std::vector<std::string> pictures;
  if (outputs.pictures) {
    const std::string residuals = SiblingPath(cameramodel_path, ".residuals.png");
    const std::string coverage = SiblingPath(cameramodel_path, ".coverage.png");
    FRESCO_RETURN_IF_ERROR(WriteImageAtomic(residuals, DrawResiduals(run)));
    FRESCO_RETURN_IF_ERROR(WriteImageAtomic(coverage, DrawCoverage(run)));
    pictures = {residuals, coverage};
    const cv::Mat uncertainty = DrawUncertainty(run);
    if (!uncertainty.empty()) {
      pictures.push_back(SiblingPath(cameramodel_path, ".uncertainty.png"));
      FRESCO_RETURN_IF_ERROR(WriteImageAtomic(pictures.back(), uncertainty));
    }
  }
  if (!outputs.corners_vnl.empty())
    FRESCO_RETURN_IF_ERROR(WriteCornersVnl(outputs.corners_vnl, run.views, request.board));
  return WriteCalibration(cameramodel_path, request, run, pictures, optimization_inputs_missing);
}

}  // namespace fresco::calib
