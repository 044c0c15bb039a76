// Measures how soon the app's calibration worker is free after Cancel during a solve (not a
// test: figures for docs/results.md). Detects the board in a folder as the Calibration panel
// does, then for each delay starts a solve, waits that long, presses Cancel and times until
// the worker is idle again (the panel's buttons usable), saying which fit was under way.
//   calibration_cancel_measure IMAGES_DIR BOARD [MODEL] [DELAY_S...]
// MODEL defaults to auto (every model tried, the splined one too); delays to 0.5 1 2 4 8 16.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "calib/board.h"
#include "ui/core/calibration_runner.h"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr,
                 "usage: calibration_cancel_measure IMAGES_DIR BOARD [MODEL] [DELAY_S...]\n");
    return 2;
  }
  using Clock = std::chrono::steady_clock;
  fresco::calib::CalibrateRequest request;
  request.images_dir = argv[1];
  const fresco::Status board = fresco::calib::ParseBoardSpec(argv[2], "BOARD", &request.board);
  if (!board.ok()) {
    std::fprintf(stderr, "%s\n", board.message().c_str());
    return 2;
  }
  request.model = argc > 3 ? argv[3] : "auto";
  std::vector<double> delays;
  for (int i = 4; i < argc; ++i) delays.push_back(std::atof(argv[i]));
  if (delays.empty()) delays = {0.5, 1, 2, 4, 8, 16};

  fresco::CalibrationRunner runner;
  Clock::time_point start = Clock::now();
  runner.Detect(request);
  runner.WaitIdle();
  std::printf("detected %zu views in %.1f s\n", runner.Snapshot()->run.views.size(),
              std::chrono::duration<double>(Clock::now() - start).count());
  start = Clock::now();
  runner.Solve();
  runner.WaitIdle();
  const double whole = std::chrono::duration<double>(Clock::now() - start).count();
  std::printf("a whole solve (%s): %.1f s, %d fits, %s\n", request.model.c_str(), whole,
              runner.Snapshot()->solves_total, runner.Snapshot()->status.c_str());
  double worst = 0;
  for (double delay : delays) {
    if (delay >= whole) continue;
    runner.Solve();
    std::this_thread::sleep_for(std::chrono::duration<double>(delay));
    const auto before = runner.Snapshot();
    const Clock::time_point pressed = Clock::now();
    runner.Cancel();
    runner.WaitIdle();
    const double free_after = std::chrono::duration<double>(Clock::now() - pressed).count();
    worst = std::max(worst, free_after);
    std::printf("cancel %5.1f s into the solve (fit %d of %d under way): idle after %.3f s; %s\n",
                delay, before->solves_done + 1, before->solves_total, free_after,
                runner.Snapshot()->status.c_str());
  }
  std::printf("slowest: idle %.3f s after Cancel\n", worst);
  return 0;
}
