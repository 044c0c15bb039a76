// The evaluation suite (pipeline/eval): the suite file's checks, the geometry and summary
// helpers, and the CI subset (projects/eval/ci.json: four tiny captures) painted with the
// defaults and with the background model and refinement switched, asserting what the
// defaults must hold against the truth.
#include <cmath>
#include <map>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pipeline/eval/eval_run.h"
#include "pipeline/eval/eval_suite.h"
#include "pipeline/eval/eval_summary.h"
#include "pipeline/rephoto/truth_view.h"
#include "tests/test_support.h"

namespace fresco::testing {
namespace {

std::string SuiteWith(const std::string& captures) {
  return R"({"fresco_eval_suite": 1, "defaults": {"size": [64, 48], "frames": 4},
             "captures": [)" +
         captures + "]}";
}

Status LoadText(const std::string& text, EvalSuite* suite) {
  const std::string path = MakeTempDir("eval-suite") + "/suite.json";
  WriteText(path, text);
  return LoadEvalSuite(path, suite);
}

TEST(EvalSuiteTest, SeedsExpandAndDefaultsMerge) {
  EvalSuite suite;
  ASSERT_TRUE(LoadText(SuiteWith(R"({"name": "a", "family": "room",
      "synth": {"scene": "builtin:cube", "frames": 6}, "seeds": [3, 4]},
      {"name": "b", "family": "plane", "synth": {"scene": "builtin:plane"}})"),
                       &suite)
                  .ok());
  ASSERT_EQ(suite.captures.size(), 3u);
  EXPECT_EQ(suite.captures[0].name, "a-s3");
  EXPECT_EQ(suite.captures[1].name, "a-s4");
  SynthJob job;
  ASSERT_TRUE(BuildSuiteCaptureJob(suite, suite.captures[1], &job).ok());
  EXPECT_EQ(job.options.seed, 4u);
  EXPECT_EQ(job.options.frames, 6);  // the capture's own value over the default
  EXPECT_EQ(job.options.width, 64);  // the default
  ASSERT_TRUE(SelectSuiteCaptures({"plane"}, &suite).ok());
  ASSERT_EQ(suite.captures.size(), 1u);
  EXPECT_EQ(suite.captures[0].name, "b");
  EXPECT_FALSE(SelectSuiteCaptures({"nothing"}, &suite).ok());
}

TEST(EvalSuiteTest, BadInputNamesTheField) {
  struct Case {
    std::string captures, expected;
  };
  const std::vector<Case> cases = {
      {R"({"name": "a", "family": "f", "synth": {"scene": "builtin:cube", "frames": 0}})",
       "captures[0].synth: frames: must be"},
      {R"({"name": "a", "family": "f", "synth": {"scene": "builtin:cube"}, "colour": 1})",
       "captures[0].colour: unknown key"},
      {R"({"name": "a b", "family": "f", "synth": {"scene": "builtin:cube"}})",
       "captures[0].name:"},
      {R"({"name": "a", "synth": {"scene": "builtin:cube"}})", "captures[0].family:"},
      {R"({"name": "a", "family": "f", "synth": {"scene": "builtin:cube", "out": "x"}})",
       "captures[0].synth.out: not allowed"},
      {R"({"name": "a", "family": "f", "synth": {"scene": "builtin:cube"}, "seeds": [-1]})",
       "captures[0].seeds[0]:"},
      {R"({"name": "a", "family": "f", "synth": {"scene": "builtin:cube"}},
          {"name": "a", "family": "f", "synth": {"scene": "builtin:cube"}})",
       "name 'a' is used twice"},
      {R"({"name": "a", "family": "f", "synth": {"scene": "builtin:cube", "streams": [{}]}})",
       "captures[0].synth: streams: the evaluation suite scores one-camera captures"},
  };
  for (const Case& c : cases) {
    EvalSuite suite;
    const Status s = LoadText(SuiteWith(c.captures), &suite);
    ASSERT_FALSE(s.ok()) << c.captures;
    EXPECT_NE(s.message().find(c.expected), std::string::npos) << s.message();
    EXPECT_NE(s.message().find("suite.json"), std::string::npos) << s.message();
  }
  EvalSuite suite;
  EXPECT_FALSE(LoadText(R"({"captures": []})", &suite).ok());
  EXPECT_FALSE(LoadText(R"({"captures": [], "extra": 1})", &suite).ok());
}

TEST(EvalScoreTest, SegmentNearPoint) {
  const Eigen::Vector3d a(0, 0, 0), b(10, 0, 0);
  EXPECT_TRUE(SegmentNearPoint(a, b, {5, 0.9, 0}, 1.0));
  EXPECT_FALSE(SegmentNearPoint(a, b, {5, 1.1, 0}, 1.0));
  EXPECT_FALSE(SegmentNearPoint(a, b, {11.5, 0, 0}, 1.0));  // beyond the end
  EXPECT_TRUE(SegmentNearPoint(a, b, {-0.5, 0, 0}, 1.0));
}

TEST(EvalSummaryTest, MedianAndWorstPerFamily) {
  std::vector<CaptureEval> r(3);
  r[0].family = "a", r[0].truth_psnr_db = 30, r[0].has_movers = true, r[0].mover_leak = 0.01;
  r[1].family = "a", r[1].truth_psnr_db = 20, r[1].mover_leak = 0.5;  // no movers: not counted
  r[2].family = "b", r[2].truth_psnr_db = 40;
  const std::vector<FamilySummary> f = SummarizeByFamily(r);
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[0].family, "a");
  EXPECT_DOUBLE_EQ(f[0].truth_psnr_db.median, 25);
  EXPECT_DOUBLE_EQ(f[0].truth_psnr_db.worst, 20);
  EXPECT_EQ(f[0].mover_leak.count, 1);
  EXPECT_DOUBLE_EQ(f[0].mover_leak.worst, 0.01);
  EXPECT_EQ(f[1].mover_leak.count, 0);
  EXPECT_EQ(f[2].family, "all");
  EXPECT_DOUBLE_EQ(f[2].truth_psnr_db.median, 30);
  EXPECT_DOUBLE_EQ(f[2].truth_psnr_db.worst, 20);
  const nlohmann::json j = nlohmann::json::parse(EvalToJson({"x=1"}, r, f));
  EXPECT_TRUE(j["captures"][1]["mover_leak"].is_null());
  EXPECT_TRUE(j["families"][1]["mover_leak"].is_null());
}

// Captures with movers get a line each on why their movers were painted; the others none.
TEST(EvalSummaryTest, WhyMoversWerePaintedPerCaptureWithMovers) {
  std::vector<CaptureEval> r(2);
  r[0].name = "with", r[0].family = "a", r[0].has_movers = true, r[0].mover_leak = 0.01;
  r[0].open_coverage = 0.95, r[0].mover_texels = 0.02;
  r[0].mover_never_open = 0.001, r[0].mover_open_masked = 0.012;
  r[0].mover_open_passed = 0.002, r[0].mover_open_replaced = 0.005;
  r[1].name = "without", r[1].family = "a";
  const std::string text = EvalToText(r, SummarizeByFamily(r));
  EXPECT_NE(text.find("| with | 1.000 | 95.0 | 2.00 | 0.10 | 1.20 | 0.20 | 0.50 |"),
            std::string::npos)
      << text;
  EXPECT_EQ(text.find("| without |", text.find("capture with movers")), std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(EvalToJson({}, r, SummarizeByFamily(r)));
  EXPECT_DOUBLE_EQ(j["captures"][0]["movers"]["texels_by_why"]["without_kept_out"], 0.012);
  EXPECT_FALSE(j["captures"][1].contains("movers"));
  // Per family: the static texels painted over the captures with movers only.
  const std::vector<FamilySummary> f = SummarizeByFamily(r);
  EXPECT_EQ(f[0].static_texels_painted.count, 1);
  EXPECT_DOUBLE_EQ(f[0].static_texels_painted.worst, 0.95);
  EXPECT_NE(text.find("| 1.000 / 1.000 | 95.0 / 95.0 |"), std::string::npos) << text;
  // Without captures with movers, no such table.
  r.erase(r.begin());
  EXPECT_EQ(EvalToText(r, SummarizeByFamily(r)).find("capture with movers"), std::string::npos);
}

// --recovery: the references are painted, and what refinement recovers of the PSNR lost to
// pose noise is a fraction between them; a capture with exact poses gets no true-pose
// reference.
TEST(EvalRecoveryTest, ReferencesBracketTheRefinedPainting) {
  EvalSuite suite;
  const Status loaded = LoadText(
      R"({"fresco_eval_suite": 1,
          "defaults": {"size": [160, 120], "supersample": 2, "lens": "pinhole", "hfov_deg": 70},
          "captures": [
            {"name": "rot", "family": "room",
             "synth": {"scene": "builtin:cube-room", "path": {"kind": "handheld", "turns": 0.5},
                       "frames": 40, "seed": 1, "pose_noise_deg": 0.5}},
            {"name": "exact", "family": "room",
             "synth": {"scene": "builtin:cube-room", "path": {"kind": "handheld", "turns": 0.5},
                       "frames": 20, "seed": 1}}]})",
      &suite);
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  EvalOptions options;
  options.cache_dir = MakeTempDir("eval-recovery");
  options.overrides = {"pipeline.refine.mode=robust"};
  options.holdout = 5;
  options.recovery = true;
  std::vector<CaptureEval> r;
  const Status s = EvaluateSuite(suite, options, &r);
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_EQ(r.size(), 2u);
  std::printf("rot: refined %.2f, off %.2f, true poses %.2f dB, recovered %.2f\n",
              r[0].truth_psnr_db, r[0].unrefined_truth_psnr_db, r[0].true_pose_truth_psnr_db,
              r[0].recovered);
  EXPECT_TRUE(r[0].noisy_poses);
  EXPECT_GT(r[0].true_pose_truth_psnr_db, r[0].unrefined_truth_psnr_db + 3);
  ASSERT_TRUE(std::isfinite(r[0].recovered));
  EXPECT_NEAR(r[0].recovered,
              (r[0].truth_psnr_db - r[0].unrefined_truth_psnr_db) /
                  (r[0].true_pose_truth_psnr_db - r[0].unrefined_truth_psnr_db),
              1e-12);
  EXPECT_GT(r[0].recovered, 0.1);  // refinement helps on a room with rotation noise
  EXPECT_FALSE(r[1].noisy_poses);
  EXPECT_TRUE(std::isfinite(r[1].unrefined_truth_psnr_db));
  EXPECT_TRUE(std::isnan(r[1].true_pose_truth_psnr_db));
  EXPECT_TRUE(std::isnan(r[1].recovered));
  const std::vector<FamilySummary> f = SummarizeByFamily(r);
  EXPECT_EQ(f.back().recovered.count, 1);
  EXPECT_EQ(f.back().exact_poses_gain_db.count, 1);
  const nlohmann::json j = nlohmann::json::parse(EvalToJson({}, r, f));
  EXPECT_DOUBLE_EQ(j["captures"][0]["refinement"]["recovered"].get<double>(), r[0].recovered);
  EXPECT_TRUE(j["captures"][1]["refinement"]["recovered"].is_null());
}

// The CI subset, painted once per setting (shared by the tests below).
class EvalCiTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    results_ = new std::map<std::string, std::map<std::string, CaptureEval>>();
    EvalSuite suite;
    const Status loaded = LoadEvalSuite(SourceDir() + "/projects/eval/ci.json", &suite);
    ASSERT_TRUE(loaded.ok()) << loaded.message();
    const std::string cache = MakeTempDir("eval-ci");
    const std::map<std::string, std::vector<std::string>> settings = {
        {"defaults", {}},
        {"background off", {"pipeline.background.mode=off"}},
        {"refine robust", {"pipeline.refine.mode=robust", "pipeline.background.mode=robust"}},
        {"select off", {"pipeline.select.enabled=false", "pipeline.background.mode=robust"}},
    };
    for (const auto& [name, overrides] : settings) {
      EvalOptions options;
      options.cache_dir = cache;
      options.overrides = overrides;
      options.holdout = 5;
      std::vector<CaptureEval> results;
      const Status s = EvaluateSuite(suite, options, &results);
      ASSERT_TRUE(s.ok()) << s.message();
      for (const CaptureEval& r : results) {
        (*results_)[name][r.name] = r;
        std::printf("%-15s %-18s truth %6.2f dB  rephoto %6.2f dB  leak %6.3f %%  %s\n",
                    name.c_str(), r.name.c_str(), r.truth_psnr_db, r.psnr_db, 100 * r.mover_leak,
                    r.generated ? "generated" : "cached");
      }
    }
  }
  static void TearDownTestSuite() { delete results_; }
  static const CaptureEval& Get(const std::string& setting, const std::string& capture) {
    return results_->at(setting).at(capture);
  }
  static std::map<std::string, std::map<std::string, CaptureEval>>* results_;
};
std::map<std::string, std::map<std::string, CaptureEval>>* EvalCiTest::results_ = nullptr;

TEST_F(EvalCiTest, EveryCaptureIsScoredAgainstTheTruth) {
  for (const auto& [setting, captures] : *results_) {
    ASSERT_EQ(captures.size(), 4u);
    for (const auto& [name, r] : captures) {
      EXPECT_GE(r.holdout_frames, 6) << setting << " " << name;
      EXPECT_EQ(r.painted_frames + r.holdout_frames, r.frames) << setting << " " << name;
      EXPECT_GT(r.completeness, 0.8) << setting << " " << name;
      EXPECT_GT(r.paint_fps, 0) << setting << " " << name;
      // Perfect poses: the painted model is close to the truth at the true poses (the
      // façade's fine texture at 160 x 120 loses most: 21.3 dB measured).
      if (name != "ci-room-movers" || setting != "background off") {
        EXPECT_GT(r.truth_psnr_db, 20.0) << setting << " " << name;
      }
    }
  }
  // The second and third settings found the captures in the cache.
  EXPECT_FALSE(Get("refine robust", "ci-room-clean").generated ||
               Get("defaults", "ci-room-clean").generated);
}

// On perfect poses the defaults (background and refinement `auto`) may cost little against
// painting without a background model, and refinement decides off: the poses are right.
TEST_F(EvalCiTest, DefaultsOnPerfectPosesAreWithinHalfADecibelOfBackgroundOff) {
  for (const char* capture : {"ci-room-clean", "ci-street-clean", "ci-facade-clean"}) {
    const AutoDecision& refine = Get("defaults", capture).decisions.refine;
    EXPECT_EQ(refine.state, AutoDecision::State::kOff) << capture << ": " << refine.Describe();
    EXPECT_GT(Get("defaults", capture).truth_psnr_db,
              Get("background off", capture).truth_psnr_db - 0.5)
        << capture;
  }
}

// On perfect poses refinement must not cost more than 0.2 dB against refinement off (it cost
// 4.8 dB on the street when every frame it could not register was kept out of painted texels).
// The street is held to 0.8 dB: refinement is not deterministic between runs there (its
// threads; 28.74-29.28 dB measured in 5 runs against 29.28 dB without it). Refinement turns
// view selection off, so the baseline is the defaults without it; both with the robust
// background model, which keeps the samples refinement misregisters out (without it the
// street loses 0.81 dB: 28.51 against 29.32; the defaults decide the background off there,
// and refinement off).
TEST_F(EvalCiTest, RefinementOnPerfectPosesCostsAtMostTwoTenthsOfADecibel) {
  for (const char* capture : {"ci-room-clean", "ci-street-clean", "ci-facade-clean"}) {
    const double allowed_db = std::string(capture) == "ci-street-clean" ? 0.8 : 0.2;
    EXPECT_GT(Get("refine robust", capture).truth_psnr_db,
              Get("select off", capture).truth_psnr_db - allowed_db)
        << capture;
  }
}

TEST_F(EvalCiTest, BackgroundModelKeepsMoversOut) {
  const CaptureEval& robust = Get("defaults", "ci-room-movers");
  const CaptureEval& off = Get("background off", "ci-room-movers");
  ASSERT_TRUE(robust.has_movers);
  // The defaults' background `auto` sees the movers and keeps the model on.
  EXPECT_EQ(robust.decisions.background.state, AutoDecision::State::kOn)
      << robust.decisions.background.Describe();
  // Measured: 5.89 % without the model, 0.000 % with it; truth 28.78 dB against 32.30 (without
  // the model the default update takes the mean of every view, which averages the movers down).
  EXPECT_GT(off.mover_leak, 0.02);  // the movers do leak without the model
  EXPECT_LT(robust.mover_leak, 0.003);
  EXPECT_LT(robust.mover_leak, off.mover_leak / 10);
  EXPECT_GT(robust.truth_psnr_db, off.truth_psnr_db + 3);
  for (const auto& [setting, captures] : *results_)
    EXPECT_FALSE(captures.at("ci-room-clean").has_movers);
}

}  // namespace
}  // namespace fresco::testing
