#include "calib/calibrate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <fnmatch.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/camera_consistency.h"
#include "pipeline/core/image_io.h"

namespace fresco::calib {
namespace {

namespace fs = std::filesystem;

constexpr double kMaxFocalStdev = 0.01;  // relative 1-sigma on fx

std::string Percent(double fraction) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.0f %%", 100 * fraction);
  return buffer;
}

bool IsImage(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tif" ||
         ext == ".tiff";
}

void CheckCoverage(CalibrationRun* run) {
  bool quadrant[2][2] = {{false, false}, {false, false}};
  for (const BoardView& v : run->views)
    for (const CornerObservation& c : v.corners)
      quadrant[(c.pixel.y() + 0.5) * 2 >= run->height][(c.pixel.x() + 0.5) * 2 >= run->width] =
          true;
  run->coverage_fraction = CoverageFraction(run->views, run->width, run->height);
  if (run->coverage_fraction < kMinCoverage)
    run->warnings.push_back("corners cover only " + Percent(run->coverage_fraction) +
                            " of the imager (16x12 cells): the lens model is extrapolated "
                            "elsewhere; show the board near the edges and corners");
  const char* names[2][2] = {{"top-left", "top-right"}, {"bottom-left", "bottom-right"}};
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i)
      if (!quadrant[j][i])
        run->warnings.push_back(std::string("no corner observed in the ") + names[j][i] +
                                " quarter of the imager");
  run->max_tilt_deg = MaxTiltDeg(run->seed);
  if (run->max_tilt_deg < kMinTiltDeg)
    run->warnings.push_back("every board is within " +
                            std::to_string(int(std::ceil(run->max_tilt_deg))) +
                            " deg of fronto-parallel: the focal length is poorly determined; "
                            "tilt the board (30-45 deg) in some images");
}

std::string Pixels(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.3f px", value);
  return buffer;
}

// A model named on the command line is not compared with others by `auto`: solve opencv8 as
// a yardstick and warn when the requested model leaves systematic residuals (its noise sigma
// more than kFitTolerance above opencv8's: auto's "does not fit"), so that a too-simple model
// is never silently written.
void CheckRequestedModel(const CalibrateRequest& request, CalibrationRun* run) {
  const std::string& model = request.model;
  if (model == "auto" || model == "opencv8" || model == "splined") return;
  SolveOptions solve;
  solve.lensmodel = MrcalLensModelName("opencv8", run->seed, run->width, run->height);
  solve.compute_uncertainty = false;
  SolveResult yardstick;
  if (!SolveIntrinsics(run->views, request.board, run->width, run->height, run->seed, solve,
                       &yardstick)
           .ok())
    return;
  const double sigma = run->Chosen().fit.noise_sigma_px;
  if (sigma > (1 + kFitTolerance) * yardstick.noise_sigma_px)
    run->warnings.push_back("the requested model " + model +
                            " leaves systematic residuals: noise sigma " + Pixels(sigma) +
                            " against " + Pixels(yardstick.noise_sigma_px) +
                            " with opencv8 (the fit tolerance is 3 %); use a richer model or "
                            "--model auto");
}

void CheckUncertainty(const CalibrateRequest& request, CalibrationRun* run) {
  const SolveResult& fit = run->Chosen().fit;
  std::vector<Eigen::Vector2d> observed;
  for (const BoardView& v : run->views)
    for (const CornerObservation& c : v.corners) observed.push_back(c.pixel);
  const double sigma = fit.noise_sigma_px * run->noise_inflation;
  const double range = MedianBoardRange_m(fit, request.board);
  run->uncertainty = ComputeUncertaintyMap(fit, run->width, run->height, range, sigma, observed);
  run->uncertainty_at_infinity =
      ComputeUncertaintyMap(fit, run->width, run->height, 0, sigma, observed);
  const UncertaintyMap& u = run->uncertainty;
  if (u.max_px < 0) {
    run->warnings.push_back("projection uncertainty could not be computed");
    return;
  }
  char range_text[32];
  std::snprintf(range_text, sizeof(range_text), "%.2f m", range);
  if (u.median_observed_px > kMaxObservedUncertaintyPx)
    run->warnings.push_back("projection uncertainty at " + std::string(range_text) + " is " +
                            Pixels(u.median_observed_px) +
                            " (median) even where boards were seen: add images");
  if (u.max_px > kMaxUncertaintyPx)
    run->warnings.push_back("projection uncertainty at " + std::string(range_text) + " reaches " +
                            Pixels(u.max_px) + " (centre " + Pixels(u.centre_px) +
                            "): the model is poorly known where no board was seen; show the "
                            "board there (see the .uncertainty.png picture)");
}

}  // namespace

std::vector<bool> CoverageCells(const std::vector<BoardView>& views, int width, int height) {
  std::vector<bool> seen(kCoverageCols * kCoverageRows, false);
  if (width <= 0 || height <= 0) return seen;
  for (const BoardView& v : views)
    for (const CornerObservation& c : v.corners) {
      const int i = std::clamp(static_cast<int>((c.pixel.x() + 0.5) * kCoverageCols / width), 0,
                               kCoverageCols - 1);
      const int j = std::clamp(static_cast<int>((c.pixel.y() + 0.5) * kCoverageRows / height), 0,
                               kCoverageRows - 1);
      seen[j * kCoverageCols + i] = true;
    }
  return seen;
}

double CoverageFraction(const std::vector<BoardView>& views, int width, int height) {
  const std::vector<bool> seen = CoverageCells(views, width, height);
  return std::count(seen.begin(), seen.end(), true) / double(seen.size());
}

double MaxTiltDeg(const CalibrationSeed& seed) {
  double max_tilt = 0;
  for (const auto& rt : seed.rt_cam_from_board) {
    const double angle = std::sqrt(rt[0] * rt[0] + rt[1] * rt[1] + rt[2] * rt[2]);
    if (angle < 1e-12) continue;
    // Board normal (0,0,1) rotated; tilt = angle between it and the camera's axis.
    const double kz = rt[2] / angle, c = std::cos(angle);
    const double nz = c + kz * kz * (1 - c);  // R(2,2) of the Rodrigues rotation
    max_tilt = std::max(max_tilt, std::acos(std::min(1.0, std::abs(nz))) * 180 / M_PI);
  }
  return max_tilt;
}

DataReadiness AssessReadiness(const std::vector<BoardView>& views, int width, int height,
                              const CalibrationSeed* seed,
                              const std::vector<std::string>& camera_doubts) {
  DataReadiness r;
  r.views = static_cast<int>(views.size());
  r.coverage_fraction = CoverageFraction(views, width, height);
  if (seed && !seed->rt_cam_from_board.empty()) r.max_tilt_deg = MaxTiltDeg(*seed);
  if (r.views < kMinViews)
    r.reasons.push_back(std::to_string(r.views) + " images with a board: a solve needs " +
                        std::to_string(kMinViews));
  else if (r.views < kFewViews)
    r.reasons.push_back(std::to_string(r.views) + " images with a board: " +
                        std::to_string(kFewViews) + " or more for a trustworthy model");
  if (r.coverage_fraction < kMinCoverage)
    r.reasons.push_back("corners cover " + Percent(r.coverage_fraction) + " of the imager (want " +
                        Percent(kMinCoverage) + "): show the board near edges and corners");
  if (r.max_tilt_deg < 0)
    r.reasons.push_back("board tilt not known yet (needs " + std::to_string(kMinViews) + " views)");
  else if (r.max_tilt_deg < kMinTiltDeg)
    r.reasons.push_back("most tilted board " + std::to_string(int(std::round(r.max_tilt_deg))) +
                        " deg (want " + std::to_string(int(kMinTiltDeg)) + "): tilt the board");
  for (const std::string& doubt : camera_doubts) r.reasons.push_back(doubt);
  r.level = r.views < kMinViews ? DataReadiness::Level::kRed
            : r.reasons.empty() ? DataReadiness::Level::kGreen
                                : DataReadiness::Level::kYellow;
  return r;
}

Status ListImages(const std::string& dir, std::vector<std::string>* paths) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return Status::Error(dir + ": IMAGES_DIR: not a folder");
  paths->clear();
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (entry.is_regular_file() && IsImage(entry.path())) paths->push_back(entry.path().string());
  if (ec) return Status::Error(dir + ": IMAGES_DIR: cannot list (" + ec.message() + ")");
  std::sort(paths->begin(), paths->end());
  if (paths->empty())
    return Status::Error(dir + ": IMAGES_DIR: no image (*.png, *.jpg, *.jpeg, *.bmp, *.tif)");
  return Status::Ok();
}

bool IsExcluded(const std::string& name, const std::vector<std::string>& patterns) {
  for (const std::string& pattern : patterns)
    if (pattern == name || fnmatch(pattern.c_str(), name.c_str(), 0) == 0) return true;
  return false;
}

bool DetectImage(const std::string& path, const CalibrateRequest& request, CalibrationRun* run,
                 BoardDetection* detection_out) {
  const std::string name = fs::path(path).filename().string();
  cv::Mat gray;
  if (!ReadImage(path, &gray, cv::IMREAD_GRAYSCALE).ok()) {
    run->rejected.push_back({name, "cannot read the image"});
    return false;
  }
  ++run->image_sizes[std::to_string(gray.cols) + "x" + std::to_string(gray.rows)];
  run->camera_doubts = ImageSizeDoubts(*run);
  if (run->width == 0) {
    run->width = gray.cols;
    run->height = gray.rows;
  } else if (gray.cols != run->width || gray.rows != run->height) {
    run->rejected.push_back(
        {name, "size " + std::to_string(gray.cols) + "x" + std::to_string(gray.rows) +
                   " differs from the first image's " + std::to_string(run->width) + "x" +
                   std::to_string(run->height)});
    return false;
  }
  BoardDetection detection = DetectBoard(gray, request.board, request.detect);
  if (detection_out) *detection_out = detection;
  run->detections.push_back({name, detection.found, detection.reason, detection.tags,
                             detection.tags_library, detection.tags_aruco,
                             detection.tags_second_look, static_cast<int>(detection.corners.size()),
                             detection.detect_ms, detection.tag_centres});
  if (!detection.found) {
    run->rejected.push_back({name, detection.reason});
    if (std::max(detection.tags_library, detection.tags_aruco) >= kWarnRejectedTags)
      run->warnings.push_back(name + ": rejected (" + detection.reason +
                              ") although the apriltag library read " +
                              std::to_string(detection.tags_library) + " and OpenCV's aruco " +
                              std::to_string(detection.tags_aruco) + " of the board's tags");
    return false;
  }
  run->views.push_back({name, std::move(detection.corners)});
  return true;
}

Status DetectViews(const CalibrateRequest& request, CalibrationRun* run) {
  std::vector<std::string> paths;
  FRESCO_RETURN_IF_ERROR(ListImages(request.images_dir, &paths));
  for (size_t i = 0; i < paths.size(); ++i) {
    const std::string name = fs::path(paths[i]).filename().string();
    if (IsExcluded(name, request.exclude)) {
      run->excluded.push_back(name);
      continue;
    }
    if (request.progress)
      request.progress("detect", static_cast<int>(i), static_cast<int>(paths.size()), name);
    DetectImage(paths[i], request, run);
  }
  if (static_cast<int>(run->views.size()) < kMinViews)
    return Status::Error(request.images_dir + ": IMAGES_DIR: the board (" + request.board.text +
                         ") was found in " + std::to_string(run->views.size()) + " of " +
                         std::to_string(paths.size()) + " images; a calibration needs at least " +
                         std::to_string(kMinViews));
  return Status::Ok();
}

Status SolveViews(const CalibrateRequest& request, CalibrationRun* run) {
  if (static_cast<int>(run->views.size()) < kMinViews)
    return Status::Failed("a calibration needs at least " + std::to_string(kMinViews) +
                          " images with a board (got " + std::to_string(run->views.size()) + ")");
  if (static_cast<int>(run->views.size()) < kFewViews)
    run->warnings.push_back("only " + std::to_string(run->views.size()) +
                            " images with a board: use 20 or more for a trustworthy model");
  // The images were read: a seed or a fit that fails is failed work, not bad input.
  FRESCO_RETURN_IF_ERROR(SeedCalibration(run->views, request.board, run->width, run->height,
                                         &run->seed, request.cancelled)
                             .Reclassified(StatusKind::kFailed));
  CheckCoverage(run);
  SelectOptions select;
  if (request.model != "auto") select.candidates = {request.model};
  select.cross_validate = request.cross_validate;
  select.all_halves = request.all_halves;
  select.solve.cancelled = request.cancelled;
  if (request.progress)
    select.progress = [&request](int done, int total, const std::string& what) {
      request.progress("solve", done, total, what);
    };
  FRESCO_RETURN_IF_ERROR(FitLensModels(run->views, request.board, run->width, run->height,
                                       run->seed, select, &run->choice)
                             .Reclassified(StatusKind::kFailed));
  for (const std::string& w : run->choice.warnings) run->warnings.push_back(w);
  CheckOneCamera(request, run);
  CheckRequestedModel(request, run);
  if (request.board.kind == BoardKind::kAprilGrid) {
    run->corner_correlation = run->Chosen().corner_correlation;
    run->noise_inflation = run->Chosen().noise_inflation;
    for (ModelTrial& t : run->choice.trials)
      for (double& s : t.fit.intrinsics_stdev) s *= run->noise_inflation;
  }
  const SolveResult& fit = run->Chosen().fit;
  CheckUncertainty(request, run);
  if (!fit.intrinsics_stdev.empty() && fit.intrinsics_stdev[0] > kMaxFocalStdev * fit.intrinsics[0])
    run->warnings.push_back("fx is uncertain: 1-sigma " +
                            Percent(fit.intrinsics_stdev[0] / fit.intrinsics[0]) +
                            " of its value; add images, tilted boards and full-imager coverage");
  return Status::Ok();
}

}  // namespace fresco::calib
