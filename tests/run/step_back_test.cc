// Stepping back through saved painting states (PaintRun::Save / Restore, RunSnapshots): paint
// to frame N keeping states every K frames, go back to M from the nearest state at or before
// it, and paint on: the buffers, per-texel models, layers, `auto` decisions and counts are
// byte for byte what painting straight to M (and on to N) gives, with the settings whose
// state reaches across frames on (the background model and update `auto` deciding on frames
// held out; refinement with its anchors; view-dependent layers; view selection).
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pipeline/core/project.h"
#include "pipeline/paint/painting_state.h"
#include "pipeline/run/paint_job.h"
#include "pipeline/run/paint_run.h"
#include "pipeline/run/run_snapshots.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

// A capture with movers (the background model has something to learn and mask).
std::string MoversCapture() {
  static const std::string project = [] {
    const std::string dir = testing::MakeTempDir("step-back") + "/capture";
    const testing::CommandResult r = testing::RunFresco(
        {"synth", "--scene", "builtin:cube-room", "--out", dir, "--frames", "36", "--size",
         "160x120", "--movers", "3", "--exposure", "0.1", "--seed", "11", "--supersample", "1"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return dir + "/project.json";
  }();
  return project;
}

struct Job {
  std::unique_ptr<PaintJob> job;
  std::unique_ptr<PaintRun> run;
  PaintSession& session() { return *job->session; }
};

Job Open(const std::vector<std::string>& overrides) {
  Job j;
  Project project;
  EXPECT_TRUE(LoadProject(MoversCapture(), overrides, &project).ok());
  PaintJobOptions options;
  options.read_frames_without_pose = true;  // as the app opens it
  EXPECT_TRUE(OpenPaintJob(project, options, &j.job).ok());
  j.run = std::make_unique<PaintRun>(j.job->session.get(), j.job->source.get(), PaintRunOptions());
  return j;
}

// Reads and paints until `frames` frames were read; saves a state into `snapshots` (when
// given) before each frame it asks for.
void PaintUpTo(Job* j, int frames, RunSnapshots* snapshots = nullptr) {
  while (j->run->stats().frames < frames) {
    if (snapshots && snapshots->Due(j->run->stats().frames)) {
      PaintRunState state;
      ASSERT_TRUE(j->run->Save(&state));
      snapshots->Add(j->run->stats().frames, std::move(state));
    }
    RunFrame frame;
    ASSERT_EQ(j->run->Next(&frame), FrameRead::kFrame);
    FrameReport report;
    if (frame.fate == FrameFate::kPaint) j->run->Paint(frame, &report);
  }
}

bool SameBytes(const cv::Mat& a, const cv::Mat& b) {
  if (a.empty() && b.empty()) return true;  // a released image keeps its type, a copy not
  if (a.size() != b.size() || a.type() != b.type()) return false;
  for (int y = 0; y < a.rows; ++y)
    if (std::memcmp(a.ptr(y), b.ptr(y), a.cols * a.elemSize()) != 0) return false;
  return true;
}

void ExpectSamePainted(const PaintedBuffer& a, const PaintedBuffer& b, const std::string& what) {
  EXPECT_TRUE(SameBytes(a.bgra, b.bgra)) << what << " bgra";
  EXPECT_TRUE(SameBytes(a.quality, b.quality)) << what << " quality";
  EXPECT_TRUE(SameBytes(a.mean_sum, b.mean_sum)) << what << " mean sums";
  EXPECT_TRUE(SameBytes(a.unmasked_sum, b.unmasked_sum)) << what << " unmasked sums";
  EXPECT_TRUE(SameBytes(a.shadow_bgra, b.shadow_bgra)) << what << " shadow";
  EXPECT_EQ(a.painted_surface_texels, b.painted_surface_texels) << what;
}

void ExpectSameDecision(const AutoDecision& a, const AutoDecision& b, const char* what) {
  EXPECT_EQ(a.state, b.state) << what;
  EXPECT_EQ(a.decided_at_frame, b.decided_at_frame) << what;
  EXPECT_EQ(a.frames_measured, b.frames_measured) << what;
  EXPECT_TRUE(a.evidence == b.evidence || (a.evidence != a.evidence && b.evidence != b.evidence))
      << what << ": " << a.evidence << " vs " << b.evidence;
}

// Everything painting made, compared to the byte; `frames` read by both.
void ExpectSamePainting(Job* a, Job* b, const std::string& at) {
  ASSERT_EQ(a->run->stats().frames, b->run->stats().frames) << at;
  EXPECT_EQ(a->run->stats().frames_painted, b->run->stats().frames_painted) << at;
  const PaintSession& sa = a->session();
  const PaintSession& sb = b->session();
  ASSERT_EQ(sa.painted().size(), sb.painted().size());
  for (size_t k = 0; k < sa.painted().size(); ++k) {
    const std::string what = at + ", buffer " + std::to_string(k);
    ExpectSamePainted(sa.painted()[k], sb.painted()[k], what);
    EXPECT_TRUE(SameBytes(sa.BackgroundImage(k), sb.BackgroundImage(k))) << what << " model";
  }
  ASSERT_EQ(sa.view_layers().size(), sb.view_layers().size()) << at;
  for (size_t l = 0; l < sa.view_layers().size(); ++l)
    for (size_t k = 0; k < sa.painted().size(); ++k)
      ExpectSamePainted(sa.view_layers()[l].painted[k], sb.view_layers()[l].painted[k],
                        at + ", layer " + std::to_string(l) + " buffer " + std::to_string(k));
  ExpectSameDecision(sa.auto_decisions().refine, sb.auto_decisions().refine, "refine");
  ExpectSameDecision(sa.auto_decisions().background, sb.auto_decisions().background, "background");
  ExpectSameDecision(sa.auto_decisions().update, sb.auto_decisions().update, "update");
  EXPECT_DOUBLE_EQ(sa.Coverage(), sb.Coverage()) << at;
}

// Paints to `n` keeping a state every `every` frames, goes back to `m` through the nearest
// and paints on to `n` again; a second job paints straight to `m` and on to `n`.
void StepBackAndCompare(const std::vector<std::string>& overrides, int every, int n, int m) {
  Job stepped = Open(overrides);
  RunSnapshots snapshots(every, size_t{1} << 30);
  PaintUpTo(&stepped, n, &snapshots);
  int from = -1;
  const PaintRunState* state = snapshots.AtOrBefore(m, &from);
  ASSERT_NE(state, nullptr);
  EXPECT_EQ(from, m / every * every);
  ASSERT_TRUE(stepped.run->Restore(*state).ok());
  EXPECT_EQ(stepped.run->stats().frames, from);
  PaintUpTo(&stepped, m);
  Job straight = Open(overrides);
  PaintUpTo(&straight, m);
  ExpectSamePainting(&stepped, &straight, "back at " + std::to_string(m));
  // The state is as it was saved after painting from it: back to it once more.
  ASSERT_TRUE(stepped.run->Restore(*state).ok());
  PaintUpTo(&stepped, m);
  ExpectSamePainting(&stepped, &straight, "back again at " + std::to_string(m));
  PaintUpTo(&stepped, n);
  PaintUpTo(&straight, n);
  ExpectSamePainting(&stepped, &straight, "on at " + std::to_string(n));
}

// The defaults: background and update `auto` (the model learning, frames held out of the
// update's decision and the decision taken between the state and the frame gone back to).
TEST(StepBack, DefaultsRepaintFromTheNearestStateAsStraightPainting) {
  StepBackAndCompare({}, 8, 34, 27);
}

TEST(StepBack, RefinementAndTheRobustModelRepaintAsStraightPainting) {
  StepBackAndCompare({"pipeline.refine.mode=robust", "pipeline.background.mode=robust"}, 6, 20, 15);
}

TEST(StepBack, ViewLayersAndViewSelectionRepaintAsStraightPainting) {
  StepBackAndCompare({"pipeline.layers.count=3", "pipeline.select.enabled=true"}, 5, 18, 12);
}

// Back to the very first frame: from the state saved before any (no reopening).
TEST(StepBack, BackToTheFirstFrameFromTheStateBeforeAny) { StepBackAndCompare({}, 10, 14, 0); }

// A state stores what painting made, not the texels never painted nor the shadows equal to
// the texels they shadow (a large model's state then fits the budget), and two states share
// what did not change between them; stepping back to either still paints on as straight
// painting (the tests above). Before, a state held a whole copy of every image.
TEST(StepBack, AStateHoldsThePaintedTexelsAndSharesWithTheOneBefore) {
  Job j = Open({});
  PaintUpTo(&j, 3);
  PaintRunState a, b;
  ASSERT_TRUE(j.run->Save(&a));
  ASSERT_TRUE(j.run->Save(&b));  // nothing painted between: the images' blocks all shared
  const size_t one = a.bytes();
  size_t raw = 0;  // the images' bytes (a whole copy of each, as a state held them before)
  for (const PaintSession::State::Part& part : a.painting->parts) raw += part.raw;
  EXPECT_LT(one, raw * 3 / 4);  // 160x120 frames of a small room: most of it painted already
  RunSnapshots snapshots(1, size_t{1} << 30);
  snapshots.Add(3, std::move(a));
  snapshots.Add(4, std::move(b));
  EXPECT_EQ(snapshots.count(), 2u);
  EXPECT_LT(snapshots.bytes(), one + one / 50);  // the frames held out, copied, aside
}

// A state that says it holds `bytes` (the budget's arithmetic only).
PaintRunState StateOf(size_t bytes) {
  auto painting = std::make_shared<PaintSession::State>();
  painting->bytes = bytes;
  PaintRunState state;
  state.painting = painting;
  return state;
}

// The budget: past it the spacing doubles (states off it dropped) and the first state stays.
TEST(RunSnapshots, OverTheBudgetTheSpacingDoublesAndTheFirstStateStays) {
  RunSnapshots snapshots(2, 350);  // room for three states of 100 bytes
  for (int frames = 0; frames <= 12; ++frames)
    if (snapshots.Due(frames)) snapshots.Add(frames, StateOf(100));
  // 0, 2, 4; at 6 the spacing becomes 4 (0, 4; 6 off it); 8; at 12 it becomes 8 (0, 8).
  EXPECT_EQ(snapshots.every(), 8);
  EXPECT_EQ(snapshots.count(), 2u);
  EXPECT_EQ(snapshots.bytes(), 200u);
  int at = -1;
  ASSERT_NE(snapshots.AtOrBefore(7, &at), nullptr);
  EXPECT_EQ(at, 0);
  ASSERT_NE(snapshots.AtOrBefore(12, &at), nullptr);
  EXPECT_EQ(at, 8);
  // A state alone over the budget is not kept, and after it none is due that would not fit.
  snapshots.Add(16, StateOf(400));
  EXPECT_EQ(snapshots.count(), 2u);
  EXPECT_FALSE(snapshots.Due(24));
}

// Saving states costly against the painting between them (a large model's painting grows as
// it goes): past a quarter of it, the spacing doubles for the states to come; those kept stay.
// Before, the full-room teddy saved 13 states in 170 frames (5.8 s CPU, 43 % of the painting's)
// and kept 3.
TEST(RunSnapshots, SavingStatesTakesAtMostAQuarterOfThePaintingAsTheyGrow) {
  RunSnapshots snapshots(10, size_t{1} << 30);
  // Painting 10 frames costs 1 (any unit); a save costs 0.1 at first, 0.13 more each time.
  double since_last = 0, save = 0.1;
  std::vector<int> saved;
  for (int frames = 0; frames <= 160; ++frames) {
    if (snapshots.Due(frames)) {
      snapshots.Add(frames, StateOf(100));
      snapshots.Costs(save, since_last);
      saved.push_back(frames);
      since_last = 0, save += 0.13;
    }
    since_last += 0.1;  // one frame painted
  }
  // 0 (nothing painted before it: nothing to compare), 10 (0.23 of 1: the spacing stays), 20
  // (0.36 of 1: 20 from here), 40 (0.49 of 2), 60 (0.62 of 2: 40), 80 (0.75 of 2: 80), 160: 7
  // saves where one every 10 frames made 17.
  EXPECT_EQ(saved, (std::vector<int>{0, 10, 20, 40, 60, 80, 160}));
  EXPECT_EQ(snapshots.count(), saved.size()) << "the states kept stay";
  int at = -1;
  ASSERT_NE(snapshots.AtOrBefore(59, &at), nullptr);
  EXPECT_EQ(at, 40);
  // Saves cheap against the painting leave the spacing as it is.
  RunSnapshots cheap(10, size_t{1} << 30);
  cheap.Costs(0.2, 1.0);
  EXPECT_EQ(cheap.every(), 10);
  cheap.Costs(0.3, 1.0);
  EXPECT_EQ(cheap.every(), 20);
}

// A budget with room for one state (a large model): the first gives way to a later one, the
// newest on the spacing replaces the one kept and the spacing doubles each time, so a step
// back far into the capture paints from a recent state, not from the first frame.
TEST(RunSnapshots, WhereOneStateFitsTheNewestReplacesItAndTheSpacingDoubles) {
  RunSnapshots snapshots(2, 150);
  for (int frames = 0; frames <= 17; ++frames)
    if (snapshots.Due(frames)) snapshots.Add(frames, StateOf(100));
  // 0; 2 replaces it (the spacing 4); 4 (8); 8 (16); 16 (32). Before, a state off the new
  // spacing dropped the one kept without taking its place: none was left.
  EXPECT_EQ(snapshots.every(), 32);
  EXPECT_EQ(snapshots.count(), 1u);
  EXPECT_EQ(snapshots.bytes(), 100u);
  int at = -1;
  ASSERT_NE(snapshots.AtOrBefore(17, &at), nullptr);
  EXPECT_EQ(at, 16);
  EXPECT_EQ(snapshots.AtOrBefore(15, &at), nullptr);
}

}  // namespace
}  // namespace fresco
