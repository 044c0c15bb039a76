#include "calib/camera_consistency.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>

#include "calib/model_select.h"
#include "calib/seed.h"

namespace fresco::calib {
namespace {

constexpr int kMinGroupViews = 4;

// The file name without its extension and digits, separators trimmed: "left03.jpg" -> "left",
// "cam1_000123.png" -> "cam_" -> "cam".
std::string Stem(const std::string& name) {
  std::string stem;
  const size_t dot = name.rfind('.');
  for (char c : name.substr(0, dot)) {
    if (!std::isdigit(static_cast<unsigned char>(c))) stem += c;
  }
  while (!stem.empty() && (stem.back() == '_' || stem.back() == '-' || stem.back() == '.'))
    stem.pop_back();
  return stem;
}

// Solves the views `indices` with `options`; noise sigma and degrees of freedom.
bool SolveGroup(const std::vector<int>& indices, const CalibrateRequest& request,
                const CalibrationRun& run, const CalibrationSeed& run_seed,
                const SolveOptions& options, double* sigma_px, double* dof) {
  std::vector<BoardView> views;
  CalibrationSeed seed = run_seed;
  seed.rt_cam_from_board.clear();
  for (int i : indices) {
    views.push_back(run.views[i]);
    seed.rt_cam_from_board.push_back(run_seed.rt_cam_from_board[i]);
  }
  SolveResult fit;
  if (!SolveIntrinsics(views, request.board, run.width, run.height, seed, options, &fit).ok())
    return false;
  *sigma_px = fit.noise_sigma_px;
  *dof = std::max(1, 2 * fit.corners_used - fit.num_states);
  return std::isfinite(*sigma_px) && *sigma_px > 0;
}

// `joint`: the fit of every view with options.lensmodel, when there is one (else solved here).
SplitTest RunSplit(const std::string& how, const std::vector<int>& a, const std::vector<int>& b,
                   const CalibrateRequest& request, const CalibrationRun& run,
                   const CalibrationSeed& seed, const SolveOptions& options,
                   const SolveResult* joint) {
  SplitTest test;
  test.how = how;
  for (int i : a) test.group_a.push_back(run.views[i].name);
  for (int i : b) test.group_b.push_back(run.views[i].name);
  std::vector<int> both = a;
  both.insert(both.end(), b.begin(), b.end());
  double sigma_a = 0, sigma_b = 0, dof_a = 0, dof_b = 0, dof = 0;
  const bool reuse =
      joint != nullptr && both.size() == run.views.size() && joint->lensmodel == options.lensmodel;
  if (reuse) test.joint_sigma_px = joint->noise_sigma_px;
  if (!SolveGroup(a, request, run, seed, options, &sigma_a, &dof_a) ||
      !SolveGroup(b, request, run, seed, options, &sigma_b, &dof_b) ||
      (!reuse && !SolveGroup(both, request, run, seed, options, &test.joint_sigma_px, &dof)))
    return test;
  test.split_sigma_px =
      std::sqrt((sigma_a * sigma_a * dof_a + sigma_b * sigma_b * dof_b) / (dof_a + dof_b));
  test.ratio = test.joint_sigma_px / test.split_sigma_px;
  return test;
}

std::string Figure(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

// The split tests and the doubts they raise (appended to run->split_tests and
// run->camera_doubts, which the callers start with the image sizes' doubts), with `seed` (a board
// pose per view) and `options`; `joint` as in RunSplit.
void RunSplitTests(const CalibrateRequest& request, const CalibrationSeed& seed,
                   const SolveOptions& options, const SolveResult* joint, CalibrationRun* run) {
  const int n = static_cast<int>(run->views.size());
  if (n < 2 * kMinGroupViews || static_cast<int>(seed.rt_cam_from_board.size()) != n) return;
  // Split 1: by file-name stem (the two largest groups).
  std::map<std::string, std::vector<int>> by_stem;
  for (int i = 0; i < n; ++i) by_stem[Stem(run->views[i].name)].push_back(i);
  std::vector<std::pair<std::string, std::vector<int>>> stems(by_stem.begin(), by_stem.end());
  std::sort(stems.begin(), stems.end(),
            [](const auto& x, const auto& y) { return x.second.size() > y.second.size(); });
  std::vector<std::vector<int>> done;
  if (stems.size() >= 2 && static_cast<int>(stems[1].second.size()) >= kMinGroupViews) {
    run->split_tests.push_back(
        RunSplit("file names " + stems[0].first + "* / " + stems[1].first + "*", stems[0].second,
                 stems[1].second, request, *run, seed, options, joint));
    done.push_back(stems[0].second);
    done.push_back(stems[1].second);
  }
  // Split 2: first and second half in name order (one camera's images, then another's).
  std::vector<int> first, second;
  for (int i = 0; i < n; ++i) (i < n / 2 ? first : second).push_back(i);
  if (std::find(done.begin(), done.end(), first) == done.end() &&
      std::find(done.begin(), done.end(), second) == done.end())
    run->split_tests.push_back(RunSplit("first / second half by name", first, second, request, *run,
                                        seed, options, joint));
  for (const SplitTest& t : run->split_tests) {
    if (t.ratio <= kSplitSigmaRatio) continue;
    run->camera_doubts.push_back(
        "the images look like two cameras: split " + t.how + " (" +
        std::to_string(t.group_a.size()) + " and " + std::to_string(t.group_b.size()) +
        " images), one camera fits them with corner noise " + Figure("%.3f px", t.joint_sigma_px) +
        ", two cameras with " + Figure("%.3f px", t.split_sigma_px) + " (ratio " +
        Figure("%.2f", t.ratio) + ", over " + Figure("%.2f", kSplitSigmaRatio) +
        "); calibrate each camera from its own images (exclude the others)");
  }
}

}  // namespace

std::vector<std::string> ImageSizeDoubts(const CalibrationRun& run) {
  if (run.image_sizes.size() < 2) return {};
  std::string sizes;
  for (const auto& [size, count] : run.image_sizes)
    sizes += (sizes.empty() ? "" : ", ") + size + ": " + std::to_string(count);
  return {"images of " + std::to_string(run.image_sizes.size()) + " sizes in one folder (" + sizes +
          "): they come from different cameras; only the " + std::to_string(run.width) + "x" +
          std::to_string(run.height) +
          " ones are used. Calibrate each camera from its own images (exclude the others)"};
}

void CheckOneCamera(const CalibrateRequest& request, CalibrationRun* run) {
  run->camera_doubts = ImageSizeDoubts(*run);
  run->split_tests.clear();
  if (run->choice.chosen >= 0) {
    SolveOptions options;
    options.lensmodel = run->Chosen().lensmodel;
    if (run->Chosen().short_name == "splined")
      options.lensmodel = MrcalLensModelName("opencv8", run->seed, run->width, run->height);
    options.compute_uncertainty = false;
    RunSplitTests(request, run->seed, options, &run->Chosen().fit, run);
  }
  for (const std::string& doubt : run->camera_doubts) run->warnings.push_back(doubt);
}

void CheckOneCameraBeforeSolving(const CalibrateRequest& request, CalibrationRun* run) {
  run->camera_doubts = ImageSizeDoubts(*run);
  run->split_tests.clear();
  CalibrationSeed seed;
  if (static_cast<int>(run->views.size()) < 2 * kMinGroupViews ||
      !SeedCalibration(run->views, request.board, run->width, run->height, &seed).ok())
    return;
  SolveOptions options;
  options.lensmodel = MrcalLensModelName(kBeforeSolvingModel, seed, run->width, run->height);
  options.compute_uncertainty = false;
  RunSplitTests(request, seed, options, nullptr, run);
}

}  // namespace fresco::calib
