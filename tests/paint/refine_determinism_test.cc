// Refinement is deterministic: the same capture painted twice in one process, and once more
// with another thread count, gives bit-identical buffers and the same refinement reports,
// whatever the threads' timing (which buffer ran on which thread, what each ran before,
// in what order they finished). The robust mode, with the frame's pose corrected from all
// buffers' matches (the default) and with one homography per buffer; the background model
// on (its moves follow the anchors').
#include <cstdio>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "tests/paint/refine_scenario.h"

namespace fresco::testing {
namespace {

struct Painting {
  PaintedScenario painted;
  std::vector<std::string> reports;  // per frame: the refine stage's figures and words
};

// Everything the refine stage reports but its timings, printed exactly.
std::string Describe(const StageReport& r) {
  std::string out;
  char value[64];
  for (const auto& [name, v] : r.metrics) {
    if (name.size() > 3 && name.compare(name.size() - 3, 3, "_ms") == 0) continue;
    std::snprintf(value, sizeof(value), "%.17g", v);
    out += name + "=" + value + " ";
  }
  for (const auto& [name, words] : r.notes) out += name + ": " + words + "; ";
  return out;
}

Painting Paint(const RefineScenario& scenario, const PipelineOptions& options, int threads) {
  const int threads_before = cv::getNumThreads();
  cv::setNumThreads(threads);
  Painting run;
  EXPECT_TRUE(PaintScenario(scenario, scenario.capture.given_poses, options, &run.painted,
                            [&](const FrameReport& report) {
                              const StageReport* refine = report.Stage("refine");
                              run.reports.push_back(refine ? Describe(*refine) : "no refine");
                            })
                  .ok());
  cv::setNumThreads(threads_before);
  return run;
}

// Buffers whose painted colours or qualities differ (any texel), and the first frame whose
// refinement reports differ.
void ExpectIdentical(const Painting& a, const Painting& b, const char* what) {
  const std::vector<PaintedBuffer>& pa = a.painted.session->painted();
  const std::vector<PaintedBuffer>& pb = b.painted.session->painted();
  ASSERT_EQ(pa.size(), pb.size());
  int differing = 0;
  double largest = 0;
  for (size_t i = 0; i < pa.size(); ++i) {
    const double colour = cv::norm(pa[i].bgra, pb[i].bgra, cv::NORM_INF);
    const double quality = cv::norm(pa[i].quality, pb[i].quality, cv::NORM_INF);
    if (colour != 0 || quality != 0) ++differing;
    largest = std::max(largest, colour);
  }
  EXPECT_EQ(differing, 0) << what << ": " << differing << " of " << pa.size()
                          << " buffers differ (largest colour difference " << largest << ")";
  ASSERT_EQ(a.reports.size(), b.reports.size());
  for (size_t f = 0; f < a.reports.size(); ++f) {
    if (a.reports[f] == b.reports[f]) continue;
    ADD_FAILURE() << what << ": frame " << f << "'s refinement differs:\n  " << a.reports[f]
                  << "\n  " << b.reports[f];
    break;
  }
}

class RefineDeterminism : public ::testing::TestWithParam<bool> {
 protected:
  static void SetUpTestSuite() {
    scenario_ = new RefineScenario;
    ASSERT_TRUE(MakeRefineScenario(90, 0.5, scenario_).ok());
  }
  static void TearDownTestSuite() { delete scenario_; }
  static RefineScenario* scenario_;
};
RefineScenario* RefineDeterminism::scenario_ = nullptr;

TEST_P(RefineDeterminism, SameCaptureSameBuffersWhateverTheThreads) {
  PipelineOptions options;
  options.refine.mode = RefineMode::kRobust;
  options.refine.pose = GetParam();
  const Painting first = Paint(*scenario_, options, 2);
  const Painting second = Paint(*scenario_, options, 2);
  const Painting serial = Paint(*scenario_, options, 1);
  std::printf("pose %s: %d, %d, %d registrations applied\n", GetParam() ? "on" : "off",
              first.painted.refined, second.painted.refined,
              serial.painted.refined);
  EXPECT_GT(first.painted.refined, 0);  // refinement ran: the test can fail
  ExpectIdentical(first, second, "two runs");
  ExpectIdentical(first, serial, "2 threads against 1");
}

INSTANTIATE_TEST_SUITE_P(Pose, RefineDeterminism, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& info) {
                           return info.param ? std::string("PoseOn") : std::string("PoseOff");
                         });

}  // namespace
}  // namespace fresco::testing
