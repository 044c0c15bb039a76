// Painting in shards and merging (`fresco run --shard I/N`, `fresco merge`; CONTRACT.md,
// "Beyond one machine"): the merged outputs are the unsharded run's, bit for bit (painted.gltf,
// its .bin, every atlas page; texels and coverage in metrics.json), on the default project
// (one stream, the defaults: joint pose check, `auto` modes) and on a capture of two streams,
// for N = 1, 2 and 4; each shard paints only its charts and skips frames; bad shard specs and
// bad sets of parts are refused with exit 2 naming them, leaving the output folder untouched;
// so is a pre-pass file written for other settings.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/test_support.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::MakeTempDir;
using testing::ReadText;
using testing::RunFresco;
using testing::WriteText;

// Every file of `dir` (not sub-folders) and its bytes.
std::map<std::string, std::string> Files(const std::string& dir) {
  std::map<std::string, std::string> files;
  for (const fs::directory_entry& e : fs::directory_iterator(dir))
    if (e.is_regular_file()) files[e.path().filename().string()] = ReadText(e.path().string());
  return files;
}

json Metrics(const std::string& dir) { return json::parse(ReadText(dir + "/metrics.json")); }

// Runs `project` unsharded and in 1, 2 and 4 shards, merges each set, and compares.
// `own_charts_only`: settings that couple no charts, so a shard that reads the charts' layout
// from the pre-pass file builds only its own charts' texels; the pre-pass job (--prepass-only,
// which lays the charts out without building them) writes the file first.
void ExpectMergedEqualsUnsharded(const std::string& project, const std::string& tag,
                                 const std::vector<std::string>& sets = {},
                                 bool own_charts_only = false) {
  const std::string work = MakeTempDir(tag);
  auto run = [&](std::vector<std::string> args) {
    for (const std::string& set : sets) args.insert(args.end(), {"--set", set});
    args.push_back("--quiet");
    const testing::CommandResult r = RunFresco(args);
    EXPECT_EQ(r.exit_code, 0) << r.err;
  };
  run({"run", project, "--out", work + "/whole"});
  const std::map<std::string, std::string> whole = Files(work + "/whole");
  const json whole_metrics = Metrics(work + "/whole");
  for (int n : {1, 2, 4}) {
    std::vector<std::string> merge = {"merge"};
    // own_charts_only: the pre-pass job writes the file (its charts laid out, not built).
    const std::string prepass = work + "/n" + std::to_string(n) + ".prepass";
    if (n > 1 && own_charts_only) run({"run", project, "--prepass", prepass, "--prepass-only"});
    long long texels_sum = 0;
    int skipped = 0;
    for (int i = n - 1; i >= 0; --i) {  // any order
      const std::string part = work + "/n" + std::to_string(n) + "/part" + std::to_string(i);
      std::vector<std::string> args = {
          "run", project, "--out", part, "--shard", std::to_string(i) + "/" + std::to_string(n)};
      // N > 1: the whole-capture pre-pass runs in the first shard, which writes it; the others
      // read it (and the merge must not tell).
      if (n > 1) args.insert(args.end(), {"--prepass", prepass});
      run(args);
      const json m = Metrics(part);
      if (n > 1 && i < n - 1 && whole_metrics.contains("joint_poses")) {
        EXPECT_EQ(m["wall"]["open_seconds"]["prepass_read"], 0.0) << "shard " << i << " of " << n;
        EXPECT_EQ(m["joint_poses"]["check_matches"], whole_metrics["joint_poses"]["check_matches"]);
      }
      const int all = whole_metrics["base_buffers"].get<int>();
      const int own = static_cast<int>(m["shard"]["buffers"].size());
      // The file's writer: the pre-pass job, else the first shard to run (the last).
      const bool read_layout = n > 1 && (own_charts_only || i < n - 1);
      EXPECT_EQ(m["shard"]["buffers_built"], own_charts_only && read_layout ? own : all)
          << "shard " << i << " of " << n;
      EXPECT_EQ(m["shard"]["index"], i);
      EXPECT_EQ(m["shard"]["count"], n);
      texels_sum += m["shard"]["texels"].get<long long>();
      skipped += m["shard"]["frames_skipped"].get<int>();
      merge.push_back(part);
    }
    EXPECT_EQ(texels_sum, whole_metrics["texels"].get<long long>()) << "N = " << n;
    if (n == 4) {
      EXPECT_GT(skipped, 0) << "no shard skipped a frame";
    }
    const std::string merged = work + "/n" + std::to_string(n) + "/merged";
    merge.insert(merge.end(), {"--out", merged, "--quiet"});
    const testing::CommandResult r = RunFresco(merge);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::map<std::string, std::string> got = Files(merged);
    ASSERT_EQ(got.size(), whole.size()) << "N = " << n;
    for (const auto& [name, bytes] : whole) {
      if (name == "metrics.json") continue;
      ASSERT_TRUE(got.count(name)) << name;
      EXPECT_TRUE(got[name] == bytes) << name << " differs from the unsharded run's, N = " << n;
    }
    const json m = Metrics(merged);
    for (const char* key : {"texels", "texels_painted", "coverage", "base_buffers", "frames",
                            "frames_painted", "buffers", "atlas", "auto"})
      EXPECT_EQ(m[key], whole_metrics[key]) << key << ", N = " << n;
    EXPECT_EQ(m["shards"].size(), static_cast<size_t>(n));
    EXPECT_FALSE(m.contains("shard"));
  }
}

TEST(ShardMerge, DefaultProjectMergedEqualsUnsharded) {
  const std::string root = testing::SourceDir() + "/projects/cube-room";
  const testing::CommandResult synth =
      RunFresco({"synth", root + "/synth.json", "--if-changed"});
  ASSERT_EQ(synth.exit_code, 0) << synth.err;
  // The first 48 frames: the `auto` modes decide within them (update at frame 36, after its
  // 6th frame held out, every 6th of the 48).
  ExpectMergedEqualsUnsharded(root + "/project.json", "shard-cube-room",
                              {"pipeline.max_frames=48"});
}

// The decisions off (no frame couples the charts): shards build, hold and paint only their
// own charts, and the parts still join into the unsharded run's bytes.
TEST(ShardMerge, DecisionsOffShardsBuildOnlyTheirChartsAndMergeEqualsUnsharded) {
  const std::string root = testing::SourceDir() + "/projects/cube-room";
  const testing::CommandResult synth = RunFresco({"synth", root + "/synth.json", "--if-changed"});
  ASSERT_EQ(synth.exit_code, 0) << synth.err;
  ExpectMergedEqualsUnsharded(
      root + "/project.json", "shard-decisions-off",
      {"pipeline.max_frames=16", "pipeline.update=quality", "pipeline.refine.mode=off",
       "pipeline.refine.joint=false", "pipeline.background.mode=off"},
      /*own_charts_only=*/true);
}

TEST(ShardMerge, TwoStreamsMergedEqualsUnsharded) {
  const std::string dir = MakeTempDir("shard-streams");
  WriteText(dir + "/spec.json", R"({
  "scene": "builtin:cube-room", "out": "capture", "size": [240, 180], "frames": 40, "seed": 3,
  "streams": [
    {"name": "fixed", "path": {"kind": "fixed"}, "lens": "opencv5", "hfov_deg": 80},
    {"name": "hand", "path": {"kind": "handheld", "turns": 0.75}, "lens": "pinhole"}
  ]})");
  const testing::CommandResult synth = RunFresco({"synth", dir + "/spec.json"});
  ASSERT_EQ(synth.exit_code, 0) << synth.err;
  ExpectMergedEqualsUnsharded(dir + "/capture/project.json", "shard-two-streams");
}

TEST(ShardMerge, BadShardSpecsAreRefused) {
  const std::string project = testing::SourceDir() + "/projects/cube-room/project.json";
  const std::string out = MakeTempDir("shard-bad") + "/out";
  for (const char* bad : {"4/4", "-1/4", "1/0", "x/2", "1", "1/2/3", "", "0/ 2"}) {
    const testing::CommandResult r = RunFresco({"run", project, "--out", out, "--shard", bad});
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.err;
    EXPECT_NE(r.err.find("--shard"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out)) << bad;
  }
}

// A pre-pass file is for its project and settings only: another run refuses it (exit 2,
// naming the file and the field) and paints nothing; --prepass-only needs the file's name.
TEST(ShardMerge, PrepassFileOfOtherSettingsIsRefused) {
  const std::string root = testing::SourceDir() + "/projects/cube-room";
  ASSERT_EQ(RunFresco({"synth", root + "/synth.json", "--if-changed"}).exit_code, 0);
  const std::string work = MakeTempDir("shard-prepass");
  const std::string prepass = work + "/prepass.json";
  const testing::CommandResult written =
      RunFresco({"run", root + "/project.json", "--prepass", prepass, "--prepass-only", "--set",
                 "pipeline.max_frames=6", "--quiet"});
  ASSERT_EQ(written.exit_code, 0) << written.err;
  ASSERT_TRUE(fs::exists(prepass));
  const testing::CommandResult other =
      RunFresco({"run", root + "/project.json", "--out", work + "/out", "--shard", "0/2",
                 "--prepass", prepass, "--set", "pipeline.max_frames=8", "--quiet"});
  EXPECT_EQ(other.exit_code, 2) << other.err;
  EXPECT_NE(other.err.find(prepass + ": settings_hash"), std::string::npos) << other.err;
  EXPECT_FALSE(fs::exists(work + "/out/painted.gltf"));
  // A layout whose triangle list is damaged is refused the same way.
  nlohmann::json file = nlohmann::json::parse(testing::ReadText(prepass));
  file["layout"]["buffers"][0]["placed"] = "not base64!";
  const std::string damaged = work + "/damaged.json";
  testing::WriteText(damaged, file.dump());
  const testing::CommandResult bad =
      RunFresco({"run", root + "/project.json", "--out", work + "/out", "--shard", "0/2",
                 "--prepass", damaged, "--set", "pipeline.max_frames=6", "--quiet"});
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(bad.err.find(damaged + ": layout.buffers[0]"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(work + "/out/painted.gltf"));
  const testing::CommandResult unnamed =
      RunFresco({"run", root + "/project.json", "--prepass-only", "--quiet"});
  EXPECT_EQ(unnamed.exit_code, 2) << unnamed.err;
  EXPECT_NE(unnamed.err.find("--prepass"), std::string::npos) << unnamed.err;
}

TEST(ShardMerge, MergeRefusesMissingRepeatedAndMixedParts) {
  const std::string root = testing::SourceDir() + "/projects/cube-room";
  ASSERT_EQ(RunFresco({"synth", root + "/synth.json", "--if-changed"}).exit_code, 0);
  const std::string work = MakeTempDir("shard-parts");
  const std::string max = "pipeline.max_frames=6";
  for (int i = 0; i < 2; ++i)
    ASSERT_EQ(RunFresco({"run", root + "/project.json", "--out", work + "/p" + std::to_string(i),
                         "--shard", std::to_string(i) + "/2", "--set", max, "--quiet"})
                  .exit_code,
              0);
  ASSERT_EQ(RunFresco({"run", root + "/project.json", "--out", work + "/other", "--shard", "1/2",
                       "--set", max, "--set", "pipeline.sampling=nearest", "--quiet"})
                .exit_code,
            0);
  ASSERT_EQ(RunFresco({"run", root + "/project.json", "--out", work + "/whole", "--set", max,
                       "--quiet"})
                .exit_code,
            0);
  // A part whose metrics.json has a field of the wrong type: named, exit 2, not a crash.
  fs::copy(work + "/p1", work + "/typed", fs::copy_options::recursive);
  json typed = Metrics(work + "/typed");
  typed["frames_painted"] = "six";
  WriteText(work + "/typed/metrics.json", typed.dump());
  fs::copy(work + "/p1", work + "/typed-rect", fs::copy_options::recursive);
  json rect = Metrics(work + "/typed-rect");
  rect["shard"]["page_rects"] = json::array({json::array({0, 1, "x", 3, 4})});
  WriteText(work + "/typed-rect/metrics.json", rect.dump());
  // A part of another layout (the glTF, which only shard 0's part holds, would differ).
  fs::copy(work + "/p1", work + "/moved", fs::copy_options::recursive);
  json moved = Metrics(work + "/moved");
  moved["shard"]["layout"] = "0123456789abcdef";
  WriteText(work + "/moved/metrics.json", moved.dump());
  const std::string out = work + "/merged";
  struct Case {
    std::vector<std::string> parts;
    std::string says;
  };
  const std::vector<Case> cases = {
      {{work + "/p0"}, "shard 1 of 2 missing"},
      {{work + "/p0", work + "/p1", work + "/p1"}, "shard 1 of 2 repeated"},
      {{work + "/p0", work + "/other"}, "settings"},
      {{work + "/p0", work + "/whole"}, "whole/metrics.json: shard: missing"},
      {{work + "/p0", work + "/none"}, "none: not a folder"},
      {{work + "/p0", work + "/typed"},
       "typed/metrics.json: frames_painted: missing or not a count"},
      {{work + "/p0", work + "/moved"}, "moved/metrics.json: shard.layout"},
      {{work + "/p0", work + "/typed-rect"},
       "typed-rect/metrics.json: shard.page_rects[0]: missing or not 5 counts"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = {"merge"};
    args.insert(args.end(), c.parts.begin(), c.parts.end());
    args.insert(args.end(), {"--out", out});
    const testing::CommandResult r = RunFresco(args);
    EXPECT_EQ(r.exit_code, 2) << c.says << ": " << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out + "/metrics.json")) << c.says;
  }
  const testing::CommandResult ok =
      RunFresco({"merge", work + "/p1", work + "/p0", "--out", out, "--quiet"});
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_TRUE(ReadText(out + "/painted_texture0.png") == ReadText(work + "/whole/painted_texture0.png"));
  // Only shard 0's part holds the glTF and its .bin; the merge takes them from there.
  EXPECT_TRUE(fs::exists(work + "/p0/painted.gltf") && fs::exists(work + "/p0/painted.bin"));
  EXPECT_FALSE(fs::exists(work + "/p1/painted.gltf") || fs::exists(work + "/p1/painted.bin"));
  EXPECT_TRUE(ReadText(out + "/painted.bin") == ReadText(work + "/whole/painted.bin"));
}

}  // namespace
}  // namespace fresco
