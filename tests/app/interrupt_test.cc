// Interrupt safety (README "Reliability"): Ctrl-C (SIGINT) or SIGTERM in the middle of `fresco
// run`, `fresco synth` and `fresco bench` leaves the output folder exactly as an earlier complete
// run left it (or empty when there was none), no temp or staging files, a one-line message saying
// so, and exit code 128 + the signal. Each test starts `fresco` as a child process, waits until it
// is under way (its first progress line), sends the signal, and compares every file of the output
// folder, byte for byte, with what was there before.
#include <signal.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/test_support.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using testing::CommandResult;
using testing::MakeTempDir;
using testing::ReadText;
using testing::RunFresco;
using testing::StartedCommand;
using testing::StartFresco;
using testing::WaitFresco;
using testing::WriteText;

// Every file under `dir` (hidden ones too), by relative path, with its bytes.
std::map<std::string, std::string> Snapshot(const std::string& dir) {
  std::map<std::string, std::string> files;
  if (!fs::exists(dir)) return files;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    const std::string rel = fs::relative(entry.path(), dir).string();
    files[rel] = entry.is_regular_file() ? ReadText(entry.path().string()) : "<folder>";
  }
  return files;
}

// Names in `dir` (recursively) that look like temp or staging files: hidden entries.
std::vector<std::string> HiddenEntries(const std::string& dir) {
  std::vector<std::string> hidden;
  if (!fs::exists(dir)) return hidden;
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    if (entry.path().filename().string().rfind('.', 0) == 0) hidden.push_back(entry.path());
  return hidden;
}

// The last line of stderr.
std::string LastLine(const std::string& err) {
  std::string text = err;
  while (!text.empty() && text.back() == '\n') text.pop_back();
  const size_t start = text.rfind('\n');
  return start == std::string::npos ? text : text.substr(start + 1);
}

// Starts `fresco args...`, waits until its stderr holds `marker` (it is under way), sends
// `signal_number`, and waits for it to end.
CommandResult InterruptWhenUnderWay(const std::vector<std::string>& args, const std::string& marker,
                                    int signal_number) {
  const StartedCommand command = StartFresco(args);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  bool under_way = false;
  while (std::chrono::steady_clock::now() < deadline) {
    if (ReadText(command.err_path).find(marker) != std::string::npos) {
      under_way = true;
      break;
    }
    int status = 0;
    if (waitpid(command.pid, &status, WNOHANG) == command.pid) {
      ADD_FAILURE() << "fresco ended before it was interrupted: " << ReadText(command.err_path);
      return CommandResult{};
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_TRUE(under_way) << "no '" << marker << "' on stderr: " << ReadText(command.err_path);
  kill(command.pid, signal_number);
  const CommandResult result = WaitFresco(command);
  std::printf("%s\n", LastLine(result.err).c_str());  // the README quotes these
  return result;
}

// A small capture (12 frames, 160x120) and a long one (3000 frames: the small one's frames
// and poses over and over, as hard links) for runs that take long enough to interrupt.
class InterruptTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const std::string root = MakeTempDir("interrupt");
    small_ = new std::string(root + "/small");
    long_ = new std::string(root + "/long");
    const CommandResult r = RunFresco({"synth", "--scene", "builtin:cube-room", "--out", *small_,
                                       "--frames", "12", "--size", "160x120", "--seed", "3"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    fs::copy(*small_, *long_, fs::copy_options::recursive);
    fs::remove_all(*long_ + "/frames");
    fs::remove_all(*long_ + "/truth");
    fs::create_directories(*long_ + "/frames");
    // images.txt: "ID QW QX QY QZ TX TY TZ CAMERA_ID NAME" then a (here empty) points line.
    std::vector<std::string> pose_fields;  // "QW ... TZ CAMERA_ID" per small frame
    std::istringstream in(ReadText(*small_ + "/sparse/images.txt"));
    for (std::string line; std::getline(in, line);) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream fields(line);
      std::string id, rest[8];
      fields >> id;
      std::string joined;
      for (std::string& f : rest) fields >> f, joined += f + " ";
      pose_fields.push_back(joined);
    }
    ASSERT_EQ(pose_fields.size(), 12u);
    std::string images = "# IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME\n";
    for (int i = 0; i < kLongFrames; ++i) {
      char name[32];
      std::snprintf(name, sizeof name, "%06d.png", i);
      fs::create_hard_link(*small_ + "/frames/" + SmallFrame(i % 12), *long_ + "/frames/" + name);
      images += std::to_string(i + 1) + " " + pose_fields[i % 12] + name + "\n\n";
    }
    WriteText(*long_ + "/sparse/images.txt", images);
    nlohmann::json project = nlohmann::json::parse(ReadText(*small_ + "/project.json"));
    project.erase("truth");
    WriteText(*long_ + "/project.json", project.dump(2));
  }
  static void TearDownTestSuite() {
    delete small_;
    delete long_;
  }
  static std::string SmallFrame(int i) {
    char name[32];
    std::snprintf(name, sizeof name, "%06d.png", i);
    return name;
  }
  static constexpr int kLongFrames = 3000;
  static std::string* small_;
  static std::string* long_;
};
std::string* InterruptTest::small_ = nullptr;
std::string* InterruptTest::long_ = nullptr;

TEST_F(InterruptTest, RunKeepsEarlierOutputsAndStagesOnSigint) {
  const std::string out = MakeTempDir("interrupt-run") + "/out";
  ASSERT_EQ(RunFresco({"run", *small_ + "/project.json", "--out", out, "--debug-images"}).exit_code,
            0);
  const auto before = Snapshot(out);
  ASSERT_TRUE(before.count("painted.gltf") && before.count("metrics.json") &&
              before.count("stages"));

  const CommandResult r = InterruptWhenUnderWay(
      {"run", *long_ + "/project.json", "--out", out, "--debug-images"}, "painting: ", SIGINT);
  EXPECT_EQ(r.exit_code, 130) << r.err;
  EXPECT_NE(LastLine(r.err).find("fresco run: interrupted by SIGINT after "), std::string::npos)
      << r.err;
  EXPECT_NE(LastLine(r.err).find("outputs of earlier runs there are kept"), std::string::npos)
      << r.err;
  EXPECT_TRUE(Snapshot(out) == before) << "the output folder changed";
  EXPECT_TRUE(HiddenEntries(out).empty()) << HiddenEntries(out)[0];
}

TEST_F(InterruptTest, RunIntoANewFolderLeavesNothingOnSigterm) {
  const std::string out = MakeTempDir("interrupt-run-new") + "/out";
  const CommandResult r = InterruptWhenUnderWay(
      {"run", *long_ + "/project.json", "--out", out, "--debug-images"}, "painting: ", SIGTERM);
  EXPECT_EQ(r.exit_code, 143) << r.err;
  EXPECT_NE(LastLine(r.err).find("fresco run: interrupted by SIGTERM"), std::string::npos) << r.err;
  EXPECT_TRUE(Snapshot(out).empty()) << Snapshot(out).begin()->first;
}

TEST_F(InterruptTest, SynthKeepsTheEarlierCaptureOnSigint) {
  const std::string dir = MakeTempDir("interrupt-synth") + "/capture";
  ASSERT_EQ(RunFresco({"synth", "--scene", "builtin:cube-room", "--out", dir, "--frames", "6",
                       "--size", "96x72"})
                .exit_code,
            0);
  const auto before = Snapshot(dir);
  ASSERT_TRUE(before.count("project.json") && before.count("frames/000005.png"));

  const CommandResult r =
      InterruptWhenUnderWay({"synth", "--scene", "builtin:cube-room", "--out", dir, "--frames",
                             "3000", "--size", "160x120", "--supersample", "1"},
                            "synth: ", SIGINT);
  EXPECT_EQ(r.exit_code, 130) << r.err;
  EXPECT_NE(LastLine(r.err).find("fresco synth: interrupted by SIGINT after "), std::string::npos)
      << r.err;
  EXPECT_NE(LastLine(r.err).find("of 3000 frames"), std::string::npos) << r.err;
  EXPECT_TRUE(Snapshot(dir) == before) << "the capture changed";
  EXPECT_TRUE(HiddenEntries(dir).empty()) << HiddenEntries(dir)[0];
}

TEST_F(InterruptTest, BenchKeepsEarlierOutputsOnSigint) {
  const std::string out = MakeTempDir("interrupt-bench") + "/out";
  ASSERT_EQ(RunFresco({"bench", *small_ + "/project.json", "--out", out, "--sweep",
                       "pipeline.sampling=nearest", "--no-baseline", "--holdout", "4"})
                .exit_code,
            0);
  const auto before = Snapshot(out);
  ASSERT_TRUE(before.count("bench.json") && before.count("pareto.png"));

  const CommandResult r = InterruptWhenUnderWay({"bench", *long_ + "/project.json", "--out", out,
                                                 "--sweep", "pipeline.sampling=nearest,bilinear"},
                                                "bench: ", SIGINT);
  EXPECT_EQ(r.exit_code, 130) << r.err;
  EXPECT_NE(LastLine(r.err).find("fresco bench: interrupted by SIGINT during run 1 of 3"),
            std::string::npos)
      << r.err;
  EXPECT_TRUE(Snapshot(out) == before) << "the output folder changed";
  EXPECT_TRUE(HiddenEntries(out).empty()) << HiddenEntries(out)[0];
}

}  // namespace
}  // namespace fresco
