// Does one calibration folder hold one camera's images? A folder mixing a stereo pair's left
// and right images solves happily into one compromise camera, so two checks:
// - image sizes: more than one size in the folder (the images of another size are rejected);
// - a split test for images of one size: the views are split into two groups (by the file
//   names' stems, e.g. left*/right*, and by the first and second half in name order); each
//   group is solved on its own with the chosen lens model, and when the corner noise sigma of
//   the joint fit exceeds the pooled sigma of the two separate fits by more than
//   kSplitSigmaRatio, the groups look like two cameras. One camera split in two fits both
//   halves with one model (opencv-chessboard-stereo's left camera, by name halves: 1.07);
//   that set's left and right images in one folder give 1.26 (tests/calib/
//   calib_one_camera_test.cc).
#pragma once

#include <string>
#include <vector>

#include "calib/calibrate.h"

namespace fresco::calib {

constexpr double kSplitSigmaRatio = 1.15;

// One line per image size beyond the first when images of several sizes were read.
std::vector<std::string> ImageSizeDoubts(const CalibrationRun& run);

// The split tests (CalibrationRun::split_tests) on run->views with the chosen model (after
// FitLensModels; opencv8 when splined was chosen, for speed). Sets run->camera_doubts (sizes
// and splits over kSplitSigmaRatio) and adds them to run->warnings.
void CheckOneCamera(const CalibrateRequest& request, CalibrationRun* run);

// The same before any solve, right after detection (the app's "enough data yet?" light):
// the views seeded, both splits and the joint fit solved with kBeforeSolvingModel. Sets
// run->split_tests and run->camera_doubts (not the warnings); a few seconds for 30 views.
constexpr const char* kBeforeSolvingModel = "opencv4";
void CheckOneCameraBeforeSolving(const CalibrateRequest& request, CalibrationRun* run);

}  // namespace fresco::calib
