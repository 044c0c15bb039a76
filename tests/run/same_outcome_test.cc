// `fresco run`, `fresco bench`, `fresco eval` and the app's painting worker (PipelineRunner,
// headless) are thin clients of one painting job, so on the same bad capture they come to
// the same outcome:
// the same one-line error (exit 2 for the CLI, "error: ..." as the app's status), or the same
// counts of frames read, painted and without a pose; live, with the time offset estimated
// before painting, too.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pipeline/core/project.h"
#include "tests/live/stream_support.h"
#include "tests/run/bad_captures.h"
#include "tests/run/play_in_app.h"
#include "tests/test_support.h"
#include "ui/core/pipeline_runner.h"

namespace fresco {
namespace {

using testing::BadCapture;
using testing::CommandResult;
using testing::MakeTempDir;
using testing::ReadText;
using testing::RunFresco;
using testing::StartFresco;
using testing::WaitFresco;

struct Outcome {
  std::string error;  // the one-line message without "error: "; "" when the run finished
  int frames = -1, painted = -1, without_pose = -1;
};

std::ostream& operator<<(std::ostream& os, const Outcome& o) {
  return os << "{error '" << o.error << "', frames " << o.frames << ", painted " << o.painted
            << ", without pose " << o.without_pose << "}";
}

// A failed command's stderr must be one line "error: MESSAGE" and its exit code 2.
std::string OneLineError(const CommandResult& r) {
  EXPECT_EQ(r.exit_code, 2) << r.err;
  std::string line = r.err;
  if (!line.empty() && line.back() == '\n') line.pop_back();
  EXPECT_EQ(line.find('\n'), std::string::npos) << "more than one line: " << r.err;
  EXPECT_EQ(line.rfind("error: ", 0), 0u) << line;
  return line.rfind("error: ", 0) == 0 ? line.substr(7) : line;
}

Outcome RunCommand(const std::string& project) {
  const std::string out = MakeTempDir("same-run") + "/out";
  const CommandResult r = RunFresco({"run", project, "--out", out, "--quiet"});
  Outcome o;
  if (r.exit_code != 0) {
    o.error = OneLineError(r);
    return o;
  }
  const nlohmann::json m = nlohmann::json::parse(ReadText(out + "/metrics.json"));
  o.frames = m["frames"], o.painted = m["frames_painted"],
  o.without_pose = m["frames_without_pose"];
  return o;
}

// One run with the project's own settings, no baseline. Held-out frames are posed frames
// bench scores instead of painting: they count as painted here.
Outcome BenchCommand(const std::string& project) {
  const std::string out = MakeTempDir("same-bench") + "/out";
  const CommandResult r = RunFresco({"bench", project, "--out", out, "--sweep",
                                     "pipeline.sampling=bilinear", "--no-baseline", "--quiet"});
  Outcome o;
  if (r.exit_code != 0) {
    o.error = OneLineError(r);
    return o;
  }
  const nlohmann::json rows = nlohmann::json::parse(ReadText(out + "/bench.json"));
  EXPECT_EQ(rows.size(), 1u);
  const nlohmann::json& row = rows.at(0);
  EXPECT_EQ(row["holdout_frames"], 1);  // counter 5 of 12 (--holdout 10)
  o.frames = row["frames"];
  o.painted = row["frames_painted"].get<int>() + row["holdout_frames"].get<int>();
  o.without_pose = row["frames_without_pose"];
  return o;
}

// The app's worker, played to the end.
Outcome AppWorker(const std::string& project_json) {
  const auto snap = testing::PlayInApp(project_json);
  Outcome o;
  if (snap->status.rfind("error: ", 0) == 0) {
    o.error = snap->status.substr(7);
    return o;
  }
  EXPECT_EQ(snap->status, "end of video");
  o.frames = snap->run.frames, o.painted = snap->run.frames_painted;
  o.without_pose = snap->run.frames_without_pose;
  return o;
}

class SameOutcomeTest : public ::testing::TestWithParam<BadCapture> {};

TEST_P(SameOutcomeTest, RunBenchAndAppAgree) {
  const std::string project = testing::MakeBadCapture(GetParam());
  const Outcome run = RunCommand(project);
  const Outcome bench = BenchCommand(project);
  const Outcome app = AppWorker(project);
  SCOPED_TRACE("run " + ::testing::PrintToString(run));
  EXPECT_EQ(bench.error, run.error);
  EXPECT_EQ(app.error, run.error);
  EXPECT_EQ(bench.frames, run.frames);
  EXPECT_EQ(app.frames, run.frames);
  EXPECT_EQ(bench.painted, run.painted);
  EXPECT_EQ(app.painted, run.painted);
  EXPECT_EQ(bench.without_pose, run.without_pose);
  EXPECT_EQ(app.without_pose, run.without_pose);
  // And the outcome is the policy's (frame_policy.h).
  const std::string dir = project.substr(0, project.rfind('/'));
  switch (GetParam()) {
    case BadCapture::kFramesSmallerThanCamera:
      EXPECT_EQ(run.error, dir + "/frames/: frame '000000.png' is 80x60 but the camera is 160x120");
      break;
    case BadCapture::kUnknownCameraId:
      EXPECT_NE(run.error.find("image '000003.png'"), std::string::npos);
      EXPECT_NE(run.error.find("CAMERA_ID 7"), std::string::npos);
      break;
    case BadCapture::kMissingPose:
      EXPECT_EQ(run.error, "");
      EXPECT_EQ(run.frames, 12);
      EXPECT_EQ(run.painted, 11);
      EXPECT_EQ(run.without_pose, 1);
      break;
    case BadCapture::kCorruptImage:
      EXPECT_EQ(run.error.rfind(dir + "/frames/000005.png: ", 0), 0u);
      break;
  }
}

INSTANTIATE_TEST_SUITE_P(BadCaptures, SameOutcomeTest,
                         ::testing::ValuesIn(testing::AllBadCaptures()), [](const auto& info) {
                           std::string name = testing::Describe(info.param);
                           for (char& c : name)
                             c = isalnum(static_cast<unsigned char>(c)) ? c : '_';
                           return name;
                         });

// A live project (frames from a folder matched by time to poses from a TCP feed) whose frames
// are smaller than its camera, with the time offset estimated: the estimate paints nothing
// of them, and `fresco run` and the app stop at the first frame with the frame policy's
// message (exit 2 from the CLI).
TEST(SameOutcome, LiveFramesSmallerThanTheCameraStopAtTheFirstFrameWhileTheOffsetIsEstimated) {
  testing::PoseServer server;
  const testing::LiveBadCapture capture = testing::MakeLiveSmallFramesCapture(server.port());
  std::thread tracker([&] { testing::ServeTrack(&server, capture.truth, 30.0, 0.0); });
  const CommandResult run = RunFresco(
      {"run", capture.project, "--out", MakeTempDir("one-door-live") + "/out", "--quiet"});
  tracker.join();
  EXPECT_EQ(run.exit_code, 2) << run.err;
  EXPECT_EQ(run.err, "error: " + capture.first_frame_error + "\n");

  std::thread tracker_again([&] { testing::ServeTrack(&server, capture.truth, 30.0, 0.0); });
  const Outcome app = AppWorker(capture.project);
  tracker_again.join();
  EXPECT_EQ(app.error, capture.first_frame_error);
}

// `fresco eval` makes its own captures (no bad one can reach it), and paints and scores them
// through the same job and held-out scorer as bench: on the capture it generated, with the
// same held-out frames, the two give the same counts and the same figures.
TEST(SameOutcome, EvalScoresItsCaptureAsBenchDoes) {
  const std::string dir = MakeTempDir("same-eval");
  testing::WriteText(dir + "/suite.json", R"({"fresco_eval_suite": 1,
      "defaults": {"size": [96, 72], "supersample": 1, "lens": "pinhole", "hfov_deg": 70},
      "captures": [{"name": "room", "family": "room", "seeds": [5],
        "synth": {"scene": "builtin:cube-room", "path": {"kind": "handheld", "turns": 0.25},
                  "frames": 20, "random_movers": 1, "pose_noise_deg": 0.3}}]})");
  const CommandResult eval = RunFresco(
      {"eval", dir + "/suite.json", "--out", dir + "/eval", "--holdout", "5", "--quiet"});
  ASSERT_EQ(eval.exit_code, 0) << eval.err;
  const nlohmann::json e =
      nlohmann::json::parse(ReadText(dir + "/eval/eval.json"))["captures"].at(0);
  const CommandResult bench = RunFresco(
      {"bench", dir + "/eval/captures/room-s5/project.json", "--out", dir + "/bench", "--holdout",
       "5", "--sweep", "pipeline.sampling=bilinear", "--no-baseline", "--quiet"});
  ASSERT_EQ(bench.exit_code, 0) << bench.err;
  const nlohmann::json b = nlohmann::json::parse(ReadText(dir + "/bench/bench.json")).at(0);
  EXPECT_EQ(e["frames"], b["frames"]);
  EXPECT_EQ(e["painted_frames"], b["frames_painted"]);
  EXPECT_EQ(e["holdout_frames"], b["holdout_frames"]);
  EXPECT_EQ(b["holdout_frames"], 4);
  for (const char* figure : {"psnr_db", "one_minus_ncc", "coverage", "completeness"})
    EXPECT_DOUBLE_EQ(e[figure].get<double>(), b[figure].get<double>()) << figure;
}

// Out of memory (0.5 mm texels on the room: several GB, in a 700 MB address space): the CLI
// exits 1 with "fresco run: MESSAGE", the app's worker shows "error: MESSAGE" as its status
// and stays up; the same message.
TEST(SameOutcome, OutOfMemoryIsOneMessageFromTheCliAndTheApp) {
  const std::string project = testing::GoodCaptureDir() + "/project.json";
  const std::vector<std::string> overrides = {"pipeline.texel_size_m=0.0005",
                                              "pipeline.max_buffer_texels=2000000000"};
  constexpr long long kLimit = 700LL << 20;
  std::vector<std::string> args = {"run", project, "--out", MakeTempDir("oom-run") + "/out",
                                   "--quiet"};
  for (const std::string& o : overrides) args.insert(args.end(), {"--set", o});
  const CommandResult cli = WaitFresco(StartFresco(args, kLimit));
  EXPECT_EQ(cli.exit_code, 1) << cli.err;
  const std::string prefix = "fresco run: ";
  ASSERT_EQ(cli.err.rfind(prefix, 0), 0u) << cli.err;
  const std::string message = cli.err.substr(prefix.size(), cli.err.find('\n') - prefix.size());
  EXPECT_NE(message.find("out of memory"), std::string::npos) << message;

  // The app's worker in a child process under the same limit; the status comes back in a file.
  const std::string status_file = MakeTempDir("oom-app") + "/status";
  const pid_t pid = fork();
  if (pid == 0) {
    const rlimit limit{static_cast<rlim_t>(kLimit), static_cast<rlim_t>(kLimit)};
    setrlimit(RLIMIT_AS, &limit);
    testing::WriteText(status_file, testing::PlayInApp(project, overrides)->status);
    _exit(0);
  }
  int wstatus = 0;
  ASSERT_EQ(waitpid(pid, &wstatus, 0), pid);
  ASSERT_TRUE(WIFEXITED(wstatus)) << "the app's worker ended by signal " << WTERMSIG(wstatus);
  ASSERT_EQ(WEXITSTATUS(wstatus), 0);
  EXPECT_EQ(ReadText(status_file), "error: " + message);
}

}  // namespace
}  // namespace fresco
