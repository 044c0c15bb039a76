// Work with no way to stop it run so that Cancel abandons it (abandonable.h): its result
// comes back byte for byte, its failure with its message, and work that would never end is
// abandoned when `cancelled` says so (before, OpenCV's seed of a calibration ran in the
// caller's process: a Cancel waited for it). The seed made in a child process is, to the bit,
// the one made here.
#include "calib/abandonable.h"

#include <unistd.h>

#include <cstring>

#include <gtest/gtest.h>

#include "calib/seed.h"
#include "tests/calib/synthetic_boards.h"

namespace fresco::calib {
namespace {

TEST(Abandonable, TheResultAndTheFailureComeBack) {
  std::string bytes;
  const std::string sent("a\0b\xff", 4);
  ASSERT_TRUE(
      RunAbandonably(
          "work", [&](std::string* out) { return *out = sent, true; }, [] { return false; }, &bytes)
          .ok());
  EXPECT_EQ(bytes, sent);
  const Status failed = RunAbandonably(
      "work", [](std::string* out) { return *out = "no board in view", false; },
      [] { return false; }, &bytes);
  EXPECT_EQ(failed.message(), "no board in view");
  const Status died = RunAbandonably(
      "work", [](std::string*) -> bool { _exit(3); }, [] { return false; }, &bytes);
  EXPECT_EQ(died.message(), "work: the process ended without its result");
}

// Work that never ends: abandoned at the second ask (0.1 s in); this test would never end
// if it were not.
TEST(Abandonable, WorkThatNeverEndsIsAbandonedWhenCancelled) {
  int asked = 0;
  std::string bytes;
  const Status status = RunAbandonably(
      "work",
      [](std::string*) {
        for (;;) pause();
        return true;
      },
      [&asked] { return ++asked >= 2; }, &bytes);
  EXPECT_EQ(status.message(), "cancelled");
  EXPECT_EQ(asked, 2);
}

TEST(Abandonable, TheSeedInAChildProcessIsTheSameAndCanBeCancelled) {
  const BoardSpec spec = testing::Spec("chessboard:10x7:0.03");
  testing::SyntheticCapture capture;
  capture.views = 10;
  const auto views = testing::SyntheticViews(spec, capture);
  CalibrationSeed here, child;
  ASSERT_TRUE(SeedCalibration(views, spec, 640, 480, &here).ok());
  ASSERT_TRUE(SeedCalibration(views, spec, 640, 480, &child, [] { return false; }).ok());
  for (auto [a, b] : {std::pair{here.fx, child.fx},
                      {here.fy, child.fy},
                      {here.cx, child.cx},
                      {here.cy, child.cy},
                      {here.k1, child.k1},
                      {here.k2, child.k2},
                      {here.rms_px, child.rms_px}})
    EXPECT_EQ(std::memcmp(&a, &b, sizeof(double)), 0) << a << " vs " << b;
  EXPECT_NEAR(here.fx, capture.intrinsics[0], 0.01 * capture.intrinsics[0]);
  ASSERT_EQ(here.rt_cam_from_board.size(), views.size());
  EXPECT_EQ(here.rt_cam_from_board, child.rt_cam_from_board);
  CalibrationSeed untouched;
  const Status cancelled = SeedCalibration(views, spec, 640, 480, &untouched, [] { return true; });
  EXPECT_EQ(cancelled.message(), "cancelled");
  EXPECT_EQ(untouched.fx, 0.0);
}

}  // namespace
}  // namespace fresco::calib
