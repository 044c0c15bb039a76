// `fresco calib solve` as a library call: read the images of a folder, detect the board in
// each (failures listed with their reason), seed, fit the lens model(s), estimate how
// correlated the corner noise is, and check the data for the classic traps (few images,
// part of the imager never observed, boards never tilted), as warnings.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "calib/model_select.h"
#include "calib/uncertainty.h"

namespace fresco::calib {

struct CalibrateRequest {
  std::string images_dir;
  // Images not to use: file names or shell globs on the name (`right*.png`); they are listed
  // in the report as excluded, not detected.
  std::vector<std::string> exclude;
  BoardSpec board;
  std::string model = "auto";  // auto or a short name (LensModelShortNames)
  DetectOptions detect;
  bool cross_validate = true;
  bool all_halves = false;  // SelectOptions::all_halves
  // Optional, for long runs: DetectViews calls it before each image ("detect", image name),
  // SolveViews before each solve ("solve", model and data); `done` of `total` finished.
  std::function<void(const std::string& stage, int done, int total, const std::string& what)>
      progress;
  // Optional: SolveViews asks it about every 0.1 s during each fit; true abandons the fit
  // under way (SolveOptions::cancelled) and the solve fails with "cancelled".
  std::function<bool()> cancelled;
};

struct RejectedImage {
  std::string name;
  std::string reason;
};

// One split test of calib/camera_consistency.h: two groups of images solved apart.
struct SplitTest {
  std::string how;  // "file names left* / right*" or "first / second half by name"
  std::vector<std::string> group_a, group_b;  // image names
  double joint_sigma_px = 0;  // corner noise sigma of one camera fitted to both groups
  double split_sigma_px = 0;  // pooled over the two groups' separate fits
  double ratio = 0;           // joint / split; 0 when a solve failed
};

// What detection found in one image, used or not (the report's per-image lines).
struct ViewDetection {
  std::string name;
  bool used = false;
  std::string reason;  // why not used ("" when used)
  int tags = 0, tags_library = 0, tags_aruco = 0, tags_second_look = 0;  // BoardDetection's
  int corners = 0;
  double detect_ms = 0;
  std::vector<Eigen::Vector2d> tag_centres;  // BoardDetection::tag_centres
};

// A warning when an image is rejected though a detector read `kWarnRejectedTags` or more of
// the board's tags in it (the tags were then left out: corners dropped as out of place).
constexpr int kWarnRejectedTags = 2;

struct CalibrationRun {
  int width = 0, height = 0;
  std::vector<BoardView> views;  // images used, sorted by name
  std::vector<RejectedImage> rejected;
  std::vector<ViewDetection> detections;   // every image detected, in order
  std::vector<std::string> excluded;       // names matched by CalibrateRequest::exclude
  std::map<std::string, int> image_sizes;  // "WxH" -> images of that size (every image read)
  // Signs that the folder mixes cameras (image sizes; one camera's fit worse than two
  // separate ones: calib/camera_consistency.h), one line each; also in `warnings`. They keep
  // the "enough data" light off green.
  std::vector<std::string> camera_doubts;
  std::vector<SplitTest> split_tests;
  CalibrationSeed seed;
  ModelChoice choice;
  std::vector<std::string> warnings;  // data traps and model-choice doubts, one line each
  // AprilGrid: correlation of the residuals of corners of one tag (same coordinate), and
  // the factor sqrt(1 + 3 rho) by which it inflates the uncertainties (1 for chessboards).
  double corner_correlation = 0;
  double noise_inflation = 1;
  double coverage_fraction = 0;  // imager cells (16 x 12) holding a corner
  double max_tilt_deg = 0;       // largest board tilt from fronto-parallel, over the views
  // Projection uncertainty of the chosen model over the imager (calib/uncertainty.h), at the
  // boards' median range and at infinity; sigma is the noise sigma times noise_inflation.
  UncertaintyMap uncertainty, uncertainty_at_infinity;

  const ModelTrial& Chosen() const { return choice.trials[choice.chosen]; }
};

// Images: *.png *.jpg *.jpeg *.bmp *.tif *.tiff in `dir` (not recursive), by name.
Status ListImages(const std::string& dir, std::vector<std::string>* paths);

// True when `name` (a file name) matches one of `patterns` (exact names or shell globs).
bool IsExcluded(const std::string& name, const std::vector<std::string>& patterns);

// Detects the board in every image not excluded. Fails (bad input) when the folder has no
// image or fewer than kMinViews images with a board.
Status DetectViews(const CalibrateRequest& request, CalibrationRun* run);

// One image of DetectViews: adds it to run->views or run->rejected (with the reason).
// `detection` (optional) receives what was found. Returns whether the image was used.
bool DetectImage(const std::string& path, const CalibrateRequest& request, CalibrationRun* run,
                 BoardDetection* detection = nullptr);

// Everything after detection. Its errors are failed work (StatusKind::kFailed): the images
// were read and detected before.
Status SolveViews(const CalibrateRequest& request, CalibrationRun* run);

constexpr int kMinViews = 3;
constexpr int kFewViews = 10;
constexpr double kMinCoverage = 0.35;  // fraction of the imager's 16 x 12 cells
constexpr double kMinTiltDeg = 20;     // at least one board this far from fronto-parallel
// Warn when the projection uncertainty at the boards' range exceeds this anywhere on the
// imager (the worst cell of the map), or kMaxObservedUncertaintyPx where corners were seen.
constexpr double kMaxUncertaintyPx = 1.0;
constexpr double kMaxObservedUncertaintyPx = 0.2;

// The imager's kCoverageCols x kCoverageRows cells holding a corner of some view (row-major),
// and their fraction.
constexpr int kCoverageCols = 16, kCoverageRows = 12;
std::vector<bool> CoverageCells(const std::vector<BoardView>& views, int width, int height);
double CoverageFraction(const std::vector<BoardView>& views, int width, int height);
// Largest board tilt from fronto-parallel over the seed's board poses (degrees).
double MaxTiltDeg(const CalibrationSeed& seed);

// "Is this enough data yet?", while images are added: red below kMinViews (no solve
// possible), yellow when a classic trap remains (fewer than kFewViews views, coverage below
// kMinCoverage, no board tilted kMinTiltDeg), green otherwise. One reason per trap.
struct DataReadiness {
  enum class Level { kRed, kYellow, kGreen };
  Level level = Level::kRed;
  int views = 0;
  double coverage_fraction = 0;
  double max_tilt_deg = -1;  // -1: unknown (no seed yet)
  std::vector<std::string> reasons;
};
// `seed`: board poses for the tilt (null = tilt unknown, which keeps the light yellow).
// `camera_doubts` (CalibrationRun::camera_doubts): each is a reason, and the light is not green.
DataReadiness AssessReadiness(const std::vector<BoardView>& views, int width, int height,
                              const CalibrationSeed* seed,
                              const std::vector<std::string>& camera_doubts = {});

}  // namespace fresco::calib
