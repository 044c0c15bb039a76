// Long jobs' progress: the elapsed and remaining time from the fraction done, COLMAP's
// progress read from its step logs, and the app's COLMAP feature count (the guide's advice).
#include <gtest/gtest.h>

#include "pipeline/poses/colmap_log_progress.h"
#include "ui/core/job_estimate.h"
#include "ui/core/new_project_bootstrap.h"

namespace fresco {
namespace {

TEST(JobEstimate, RemainingTimeFollowsTheFractionDone) {
  EXPECT_DOUBLE_EQ(RemainingSeconds(60.0, 0.25), 180.0);
  EXPECT_DOUBLE_EQ(RemainingSeconds(60.0, 1.0), 0.0);
  EXPECT_LT(RemainingSeconds(60.0, 0.0), 0.0);  // not told yet
  EXPECT_LT(RemainingSeconds(0.5, 0.5), 0.0);
  EXPECT_EQ(ElapsedAndRemainingText(83.0, 0.25), "1:23 elapsed, about 4:09 left");
  EXPECT_EQ(ElapsedAndRemainingText(12.0, 0.0), "12 s elapsed");
  EXPECT_EQ(DurationText(3723.0), "1:02:03");
}

TEST(ColmapStepProgress, TheLastProgressLineOfEachStepCounts) {
  const ColmapStepProgress features =
      ReadColmapStepProgress("Processed file [1/120]\n  Name: a.png\nProcessed file [37/120]\n", 0);
  ASSERT_TRUE(features.known);
  EXPECT_EQ(features.done, 37);
  EXPECT_EQ(features.total, 120);
  const ColmapStepProgress blocks =
      ReadColmapStepProgress("Matching block [1/3, 1/3]\nMatching block [2/3, 2/3]\n", 0);
  EXPECT_EQ(blocks.done, 5);
  EXPECT_EQ(blocks.total, 9);
  const ColmapStepProgress mapper = ReadColmapStepProgress(
      "Initializing with image pair #1 and #3\nRegistering image #4 (3)\n  => Image sees 10\n"
      "Registering image #7 (33)\n",
      66);
  EXPECT_EQ(mapper.done, 33);
  EXPECT_EQ(mapper.total, 66);
  EXPECT_NEAR(mapper.Fraction(), 0.5, 1e-12);
  EXPECT_FALSE(ReadColmapStepProgress("Elapsed time: 0.1 [minutes]\n", 66).known);
}

TEST(ColmapStepProgress, TheAppAsksForTheFeatureCountTheGuideAdvises) {
  // The guide: 1000-2000 SIFT features per image; 0 would be COLMAP's 8192.
  EXPECT_GE(NewProjectBootstrapOptions().max_features, 1000);
  EXPECT_LE(NewProjectBootstrapOptions().max_features, 2000);
}

}  // namespace
}  // namespace fresco
