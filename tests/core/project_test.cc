// The project file: defaults, strict parsing (unknown keys, wrong types, ranges, malformed
// JSON, duplicate keys), --set overrides, and load(save(p)) == p, also when saved elsewhere.
#include "pipeline/core/project.h"
#include "pipeline/core/settings.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/test_support.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

const char kMinimal[] = R"({
  "fresco": 1,
  "scene": "scene.gltf",
  "camera": "sparse/cameras.txt",
  "video": "frames/",
  "poses": "sparse/images.txt"
})";

// The minimal project with `extra` spliced in as more top-level keys.
std::string WithExtra(const std::string& extra) {
  std::string text = kMinimal;
  text.insert(text.rfind('}'), ", " + extra + "\n");
  return text;
}

Status Parse(const std::string& text, Project* project,
             const std::vector<std::string>& overrides = {}) {
  return ParseProject(text, "p.json", overrides, project);
}

std::string ParseError(const std::string& text, const std::vector<std::string>& overrides = {}) {
  Project project;
  const Status status = Parse(text, &project, overrides);
  EXPECT_FALSE(status.ok()) << "parsed without error:\n" << text;
  return status.message();
}

// Every setting whose key starts with `prefix` moved off its default, within its range: a
// setting added to a stage's header is covered by the round trips below with no edit here.
void MoveSettingsOffTheirDefaults(Project* p, const std::string& prefix) {
  for (Setting& s : DescribeSettings(p)) {
    if (s.key.rfind(prefix, 0) != 0) continue;
    const auto in_range = [&](double v) {
      return (s.min_exclusive ? v > s.min : v >= s.min) && v <= s.max;
    };
    switch (s.kind) {
      case Setting::Kind::kBool:
        *s.flag = !*s.flag;
        break;
      case Setting::Kind::kInt:
        *s.integer += in_range(*s.integer + 1) ? 1 : -1;
        break;
      case Setting::Kind::kNumber: {
        const double v = *s.number;
        double moved = v != 0 ? 0.75 * v : 0.5;
        if (!in_range(moved)) moved = std::isfinite(s.max) ? 0.5 * (v + s.max) : v + 0.5;
        *s.number = moved;
        break;
      }
      case Setting::Kind::kChoice:
        s.set_choice((s.get_choice() + 1) % static_cast<int>(s.choices.size()));
        break;
      case Setting::Kind::kText:
        break;
    }
    if (s.kind == Setting::Kind::kInt) {
      EXPECT_TRUE(in_range(*s.integer)) << s.key;
    }
    if (s.kind == Setting::Kind::kNumber) {
      EXPECT_TRUE(in_range(*s.number)) << s.key;
    }
  }
}

// A project with every setting away from its default.
Project NonDefaultProject() {
  Project p;
  p.scene = "models/castle.gltf";
  p.camera = "calib/camera.cameramodel";
  p.video = "frames/";
  p.poses = "sparse/0";
  p.time_offset_s = -0.125;
  p.live.queue_frames = 9;
  p.live.open_timeout_s = 2.5;
  p.live.read_timeout_s = 1.25;
  p.live.reconnects = 3;
  p.live.stream_clock = false;
  p.live.connect_timeout_s = 0.75;
  p.live.pose_wait_s = 0.2;
  p.live.max_pose_gap_s = 0.3;
  p.live.max_pose_extrapolate_s = 0.04;
  p.live.estimate_offset = true;
  p.live.offset_search_s = 1.5;
  p.live.offset_window_frames = 40;
  p.live.pose_reconnect_give_up_s = 12.5;
  p.live.track_offset = true;
  p.live.offset_track_every_frames = 45;
  p.live.offset_track_search_s = 0.25;
  p.live.offset_track_min_gain = 0.2;
  MoveSettingsOffTheirDefaults(&p, "pipeline.");
  p.pipeline.texel_size_m = 0.0123456789012345;  // a double that needs all its digits
  p.grouping.angle_deg = 12.5;
  p.grouping.min_chart_texels = 77;
  p.grouping.max_stretch = 1.5;
  GroupingEdit merge;
  merge.op = "merge";
  merge.groups = {3, 4, 7};
  GroupingEdit move;
  move.op = "move";
  move.triangles = {10, 11};
  move.target_group = 2;
  move.texel_size_m = 0.02;
  GroupingEdit texel;
  texel.op = "texel";
  texel.groups = {1};
  texel.texel_size_m = 0.005;
  p.grouping.edits = {merge, move, texel};
  p.grouping.groups = {GroupSpec{{0, 1, 2}, 0.0}, GroupSpec{{3, 5}, 0.01}};
  p.truth.poses = "truth/poses.tum";
  return p;
}

// The same as a version-2 file with two streams (every stream key away from its default).
Project NonDefaultProjectV2() {
  Project p = NonDefaultProject();
  p.fresco_version = 2;
  p.camera = p.video = p.poses = "";
  p.time_offset_s = 0;
  p.streams = {
      StreamSpec{"a/cameras.txt", "a/frames/", "a/images.txt", 0.25, 12.5},
      StreamSpec{"b/camera.cameramodel", "udp://127.0.0.1:5001", "tcp://127.0.0.1:6001", -0.5, 30}};
  return p;
}

const char kTwoStreams[] = R"({
  "fresco": 2,
  "scene": "scene.gltf",
  "streams": [
    {"camera": "a/cameras.txt", "video": "a/frames/", "poses": "a/images.txt"},
    {"camera": "b/cameras.txt", "video": "udp://127.0.0.1:5001", "poses": "tcp://127.0.0.1:6001",
     "time_offset_s": 0.5}
  ]
})";

// kTwoStreams with `extra` spliced in as more top-level keys.
std::string TwoStreamsWith(const std::string& extra) {
  std::string text = kTwoStreams;
  text.insert(text.rfind('}'), ", " + extra + "\n");
  return text;
}

TEST(ProjectTest, MinimalProjectGetsDefaults) {
  Project project;
  ASSERT_TRUE(Parse(kMinimal, &project).ok());
  EXPECT_EQ(project.fresco_version, 1);
  EXPECT_EQ(project.scene, "scene.gltf");
  EXPECT_EQ(project.camera, "sparse/cameras.txt");
  EXPECT_EQ(project.video, "frames/");
  EXPECT_EQ(project.poses, "sparse/images.txt");
  const Project defaults;
  EXPECT_EQ(project.pipeline, defaults.pipeline);
  EXPECT_EQ(project.grouping, defaults.grouping);
  EXPECT_EQ(project.truth, defaults.truth);
  EXPECT_EQ(project.time_offset_s, 0.0);
  EXPECT_TRUE(fs::path(project.file_path).is_absolute());
}

TEST(ProjectTest, SaveThenLoadGivesTheSameProject) {
  const std::string dir = testing::MakeTempDir("project");
  Project project = NonDefaultProject();
  project.file_path = dir + "/project.json";
  ASSERT_TRUE(SaveProject(project, project.file_path).ok());

  Project loaded;
  const Status status = LoadProject(project.file_path, {}, &loaded);
  ASSERT_TRUE(status.ok()) << status.message();
  // Field by field (operator== covers every field, file_path included) and as text.
  EXPECT_EQ(loaded.pipeline, project.pipeline);
  EXPECT_EQ(loaded.pipeline.occlusion, project.pipeline.occlusion);
  EXPECT_EQ(loaded.pipeline.background, project.pipeline.background);
  EXPECT_EQ(loaded.grouping, project.grouping);
  EXPECT_EQ(loaded.truth, project.truth);
  EXPECT_EQ(loaded.time_offset_s, project.time_offset_s);
  EXPECT_EQ(loaded, project);
  EXPECT_EQ(ProjectToJsonText(loaded), ProjectToJsonText(project));
  // Saving what was loaded changes nothing on disk.
  const std::string first = testing::ReadText(project.file_path);
  ASSERT_TRUE(SaveProject(loaded, project.file_path).ok());
  EXPECT_EQ(testing::ReadText(project.file_path), first);
}

TEST(ProjectTest, SavedFileListsEverySetting) {
  const std::string text = ProjectToJsonText(Project());
  for (const char* key : {"\"fresco\": 1",
                          "\"scene\"",
                          "\"time_offset_s\"",
                          "\"sampling\": \"bilinear\"",
                          "\"texel_size_m\"",
                          "\"max_buffer_texels\"",
                          "\"update_every\": 1",
                          "\"update\": \"auto\"",
                          "\"quality_slack\"",
                          "\"update_weight\"",
                          "\"max_frames\"",
                          "\"threads\"",
                          "\"debug_images\"",
                          "\"occlusion\"",
                          "\"tolerance_rel\"",
                          "\"tolerance_m\"",
                          "\"max_view_angle_deg\"",
                          "\"grouping\"",
                          "\"angle_deg\"",
                          "\"edits\"",
                          "\"truth\"",
                          "\"background\"",
                          "\"mode\": \"auto\"",
                          "\"window_frames\"",
                          "\"dilate_texels\"",
                          "\"atlas\"",
                          "\"page_size\"",
                          "\"select\"",
                          "\"switch_margin\"",
                          "\"min_chart_texels\"",
                          "\"max_stretch\""}) {
    EXPECT_THAT(text, HasSubstr(key));
  }
  // Pretty: one key per line.
  EXPECT_THAT(text, HasSubstr("\n  \"pipeline\": {\n"));
}

TEST(ProjectTest, SavingElsewhereKeepsPathsPointingAtTheSameFiles) {
  const std::string dir = testing::MakeTempDir("project");
  Project project = NonDefaultProject();
  project.file_path = dir + "/a/project.json";
  project.scene = "/abs/scene.gltf";       // absolute: kept
  project.video = "udp://127.0.0.1:5000";  // a stream: kept
  fs::create_directories(dir + "/b/c");
  const std::string copy_path = dir + "/b/c/copy.json";
  ASSERT_TRUE(SaveProject(project, copy_path).ok());

  Project copy;
  ASSERT_TRUE(LoadProject(copy_path, {}, &copy).ok());
  EXPECT_EQ(copy.camera, "../../a/calib/camera.cameramodel");
  EXPECT_EQ(copy.poses, "../../a/sparse/0");
  EXPECT_EQ(copy.truth.poses, "../../a/truth/poses.tum");
  EXPECT_EQ(copy.scene, "/abs/scene.gltf");
  EXPECT_EQ(copy.video, "udp://127.0.0.1:5000");
  for (auto field : {&Project::scene, &Project::camera, &Project::video, &Project::poses}) {
    EXPECT_EQ(copy.Resolve(copy.*field), project.Resolve(project.*field));
  }
  EXPECT_EQ(copy.Resolve(copy.truth.poses), project.Resolve(project.truth.poses));
  EXPECT_EQ(copy.pipeline, project.pipeline);
  EXPECT_EQ(copy.grouping, project.grouping);
}

TEST(ProjectTest, FolderPathsKeepTheirTrailingSlashWhenRebased) {
  const std::string dir = testing::MakeTempDir("project");
  Project project = NonDefaultProject();
  project.file_path = dir + "/a/project.json";
  fs::create_directories(dir + "/b");
  ASSERT_TRUE(SaveProject(project, dir + "/b/p.json").ok());
  Project copy;
  ASSERT_TRUE(LoadProject(dir + "/b/p.json", {}, &copy).ok());
  EXPECT_EQ(copy.video, "../a/frames/");
}

TEST(ProjectTest, ResolveIsRelativeToTheProjectFolder) {
  Project project;
  project.file_path = "/data/site/project.json";
  EXPECT_EQ(project.Resolve("frames/"), "/data/site/frames/");
  EXPECT_EQ(project.Resolve("../shared/cam.txt"), "/data/shared/cam.txt");
  EXPECT_EQ(project.Resolve("/abs/x.gltf"), "/abs/x.gltf");
  EXPECT_EQ(project.Resolve("device:0"), "device:0");
  EXPECT_EQ(project.Resolve("tcp://localhost:9000"), "tcp://localhost:9000");
  EXPECT_EQ(project.Resolve(""), "");
}

TEST(ProjectTest, SaveIsAtomicAndFailsOnAMissingFolder) {
  const std::string dir = testing::MakeTempDir("project");
  const Status status = SaveProject(NonDefaultProject(), dir + "/missing/p.json");
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(dir + "/missing/p.json"));
  EXPECT_TRUE(fs::is_empty(dir));
}

// ---- Bad input. --------------------------------------------------------------------------

TEST(ProjectTest, MissingFileIsNamed) {
  Project project;
  const Status status = LoadProject("/nonexistent/p.json", {}, &project);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("/nonexistent/p.json"));
  EXPECT_THAT(status.message(), HasSubstr("no such file"));
}

TEST(ProjectTest, MalformedJsonGivesLineAndColumn) {
  const std::string message = ParseError("{\n  \"fresco\": 1,\n  \"scene\" \"x\"\n}");
  EXPECT_THAT(message, StartsWith("p.json: line 3, column"));
  EXPECT_THAT(message, HasSubstr("malformed JSON"));
  EXPECT_THAT(ParseError("{\"fresco\": 1,}"), StartsWith("p.json: line 1, column"));
  EXPECT_THAT(ParseError(""), HasSubstr("malformed JSON"));
}

TEST(ProjectTest, TopLevelMustBeAnObject) {
  EXPECT_THAT(ParseError("[1, 2]"), HasSubstr("p.json: expected a JSON object"));
}

TEST(ProjectTest, UnknownKeysAreNamedByTheirPath) {
  EXPECT_EQ(ParseError(WithExtra(R"("pipeline": {"samplig": "area"})")),
            "p.json: pipeline.samplig: unknown key (did you mean 'sampling'?)");
  EXPECT_EQ(ParseError(WithExtra(R"("colour": 1)")), "p.json: colour: unknown key");
  EXPECT_THAT(ParseError(WithExtra(R"("pipeline": {"occlusion": {"enable": true}})")),
              StartsWith("p.json: pipeline.occlusion.enable: unknown key"));
  EXPECT_THAT(ParseError(WithExtra(R"("grouping": {"edits": [{"op": "merge", "grups": [1]}]})")),
              StartsWith("p.json: grouping.edits[0].grups: unknown key"));
}

TEST(ProjectTest, WrongTypesAreNamed) {
  EXPECT_THAT(ParseError(WithExtra(R"("pipeline": {"update_every": "20"})")),
              StartsWith("p.json: pipeline.update_every: expected an integer, got string"));
  EXPECT_EQ(ParseError(WithExtra(R"("pipeline": {"update_every": 2.5})")),
            "p.json: pipeline.update_every: expected an integer, got number 2.5");
  EXPECT_THAT(ParseError(WithExtra(R"("pipeline": {"debug_images": 1})")),
              StartsWith("p.json: pipeline.debug_images: expected true or false"));
  EXPECT_THAT(ParseError(WithExtra(R"("pipeline": 3)")),
              StartsWith("p.json: pipeline: expected an object, got number"));
  EXPECT_THAT(ParseError(WithExtra(R"("time_offset_s": "0.5")")),
              StartsWith("p.json: time_offset_s: expected a number, got string"));
  EXPECT_THAT(ParseError(WithExtra(R"("grouping": {"edits": {}})")),
              StartsWith("p.json: grouping.edits: expected an array"));
  EXPECT_THAT(
      ParseError(WithExtra(R"("grouping": {"edits": [{"op": "merge", "groups": [1, "x"]}]})")),
      StartsWith("p.json: grouping.edits[0].groups[1]: expected an integer"));
  std::string text = kMinimal;
  text.replace(text.find("\"scene.gltf\""), 12, "42");
  EXPECT_THAT(ParseError(text), StartsWith("p.json: scene: expected a string, got number 42"));
  // 20.0 is the integer 20.
  Project project;
  ASSERT_TRUE(Parse(WithExtra(R"("pipeline": {"update_every": 20.0})"), &project).ok());
  EXPECT_EQ(project.pipeline.update_every, 20);
}

TEST(ProjectTest, RequiredKeysAndVersion) {
  for (const char* key : {"fresco", "scene", "camera", "video", "poses"}) {
    std::string text = kMinimal;
    const size_t start = text.find(std::string("\"") + key + "\"");
    const size_t end = text.find('\n', start);
    text.erase(start, end - start + 1);
    if (std::string(key) == "poses") text.replace(text.rfind(','), 1, "");
    EXPECT_EQ(ParseError(text), std::string("p.json: ") + key + ": missing required key");
  }
  for (const char* version : {"0", "3"}) {
    std::string text = kMinimal;
    text.replace(text.find("\"fresco\": 1"), 11, std::string("\"fresco\": ") + version);
    EXPECT_THAT(ParseError(text),
                StartsWith(std::string("p.json: fresco: unsupported version ") + version));
  }
  std::string empty = kMinimal;
  empty.replace(empty.find("\"frames/\""), 9, "\"\"");
  EXPECT_EQ(ParseError(empty), "p.json: video: must not be empty");
}

TEST(ProjectTest, EnumsAndRangesAreChecked) {
  EXPECT_EQ(ParseError(WithExtra(R"("pipeline": {"sampling": "cubic"})")),
            "p.json: pipeline.sampling: 'cubic' is not one of \"nearest\", \"bilinear\" or "
            "\"area\"");
  EXPECT_THAT(ParseError(WithExtra(R"("pipeline": {"update": "newest"})")),
              StartsWith("p.json: pipeline.update: 'newest' is not one of \"latest\", "
                         "\"quality\", \"mean\", \"sharp_mean\" or \"auto\""));
  EXPECT_THAT(ParseError(WithExtra(R"("pipeline": {"quality_slack": 1.5})")),
              StartsWith("p.json: pipeline.quality_slack: must be in [0, 1], got 1.5"));
  EXPECT_EQ(ParseError(WithExtra(R"("pipeline": {"update_every": 0})")),
            "p.json: pipeline.update_every: must be >= 1, got 0");
  EXPECT_EQ(ParseError(WithExtra(R"("pipeline": {"texel_size_m": -0.01})")),
            "p.json: pipeline.texel_size_m: must be >= 0, got -0.01");
  EXPECT_EQ(ParseError(WithExtra(R"("pipeline": {"occlusion": {"max_view_angle_deg": 95}})")),
            "p.json: pipeline.occlusion.max_view_angle_deg: must be in (0, 90], got 95");
  EXPECT_THAT(ParseError(WithExtra(R"("pipeline": {"occlusion": {"max_view_angle_deg": 0}})")),
              HasSubstr("must be in (0, 90]"));
  EXPECT_THAT(ParseError(WithExtra(R"("grouping": {"angle_deg": 181})")),
              StartsWith("p.json: grouping.angle_deg: must be in [0, 180]"));
  EXPECT_THAT(ParseError(WithExtra(R"("grouping": {"edits": [{"op": "glue"}]})")),
              StartsWith("p.json: grouping.edits[0].op: 'glue' is not one of"));
  EXPECT_EQ(ParseError(WithExtra(R"("grouping": {"edits": [{"groups": [1]}]})")),
            "p.json: grouping.edits[0].op: missing required key");
  EXPECT_THAT(ParseError(WithExtra(R"("pipeline": {"threads": 99999999999})")),
              StartsWith("p.json: pipeline.threads: integer out of range"));
}

TEST(ProjectTest, DuplicateKeysAreErrors) {
  EXPECT_EQ(ParseError(WithExtra(R"("pipeline": {"update_every": 2, "update_every": 3})")),
            "p.json: pipeline.update_every: duplicate key");
  EXPECT_EQ(ParseError(WithExtra(R"("scene": "other.gltf")")), "p.json: scene: duplicate key");
  EXPECT_EQ(ParseError(WithExtra(
                R"("grouping": {"edits": [{"op": "merge"}, {"op": "split", "op": "move"}]})")),
            "p.json: grouping.edits[1].op: duplicate key");
}

// ---- --set overrides. --------------------------------------------------------------------

TEST(ProjectTest, SetOverridesByJsonPath) {
  Project project;
  const Status status =
      Parse(kMinimal, &project,
            {"pipeline.sampling=nearest", "pipeline.update_every=20",
             "pipeline.occlusion.enabled=false", "video=other/frames/", "time_offset_s=0.25",
             "grouping.edits=[{\"op\": \"split\", \"groups\": [2]}]"});
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(project.pipeline.sampling, SamplingMode::kNearest);
  EXPECT_EQ(project.pipeline.update_every, 20);
  EXPECT_FALSE(project.pipeline.occlusion.enabled);
  EXPECT_EQ(project.video, "other/frames/");
  EXPECT_EQ(project.time_offset_s, 0.25);
  ASSERT_EQ(project.grouping.edits.size(), 1u);
  EXPECT_EQ(project.grouping.edits[0].op, "split");
  // Into an array element, and overriding what the file says.
  ASSERT_TRUE(Parse(WithExtra(R"("pipeline": {"update_every": 5}, "grouping": {"edits": )"
                              R"([{"op": "merge"}]})"),
                    &project, {"grouping.edits.0.op=move", "pipeline.update_every=7"})
                  .ok());
  EXPECT_EQ(project.grouping.edits[0].op, "move");
  EXPECT_EQ(project.pipeline.update_every, 7);
}

TEST(ProjectTest, SetErrorsNameTheKey) {
  EXPECT_EQ(ParseError(kMinimal, {"pipeline.nope=1"}),
            "p.json: pipeline.nope: unknown key (from --set pipeline.nope=1)");
  EXPECT_THAT(ParseError(kMinimal, {"nope.deeper=1"}),
              StartsWith("p.json: nope: unknown key (from --set nope.deeper=1)"));
  EXPECT_THAT(ParseError(kMinimal, {"pipeline.update_every=often"}),
              StartsWith("p.json: pipeline.update_every: expected an integer, got string "
                         "\"often\" (from --set pipeline.update_every=often)"));
  EXPECT_THAT(ParseError(kMinimal, {"pipeline.update_every"}),
              StartsWith("p.json: --set pipeline.update_every: expected KEY=VALUE"));
  EXPECT_THAT(ParseError(kMinimal, {"scene.x=1"}),
              StartsWith("p.json: --set scene.x=1: scene: is a string"));
  EXPECT_THAT(ParseError(kMinimal, {"grouping.edits.3.op=merge"}),
              HasSubstr("grouping.edits: no element '3'"));
  EXPECT_THAT(ParseError(kMinimal, {"pipeline..sampling=area"}), HasSubstr("empty name"));
}

TEST(ProjectTest, SamplingModeNames) {
  for (SamplingMode mode : {SamplingMode::kNearest, SamplingMode::kBilinear, SamplingMode::kArea}) {
    SamplingMode parsed;
    ASSERT_TRUE(SamplingModeFromName(SamplingModeName(mode), &parsed));
    EXPECT_EQ(parsed, mode);
  }
  SamplingMode parsed;
  EXPECT_FALSE(SamplingModeFromName("cubic", &parsed));
}

// Version 2: several video streams, each with its own camera, video, poses and time offset.
TEST(ProjectTest, Version2ListsStreams) {
  Project project;
  const Status status = Parse(kTwoStreams, &project);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(project.fresco_version, 2);
  EXPECT_EQ(project.camera, "");
  ASSERT_EQ(project.streams.size(), 2u);
  EXPECT_EQ(project.streams[0], (StreamSpec{"a/cameras.txt", "a/frames/", "a/images.txt", 0.0}));
  EXPECT_EQ(project.streams[1].video, "udp://127.0.0.1:5001");
  EXPECT_EQ(project.streams[1].time_offset_s, 0.5);
  EXPECT_EQ(project.Streams(), project.streams);
  EXPECT_EQ(project.StreamKey(1, "video"), "streams[1].video");
  EXPECT_FALSE(CheckOneStream(project, "fresco bench").ok());
  EXPECT_EQ(CheckOneStream(project, "fresco bench").message(),
            project.file_path +
                ": streams: 2 video streams, but fresco bench reads one (fresco "
                "run paints several)");
  // A version-1 view of one stream, for code that reads one.
  const Project second = project.ForStream(1);
  EXPECT_EQ(second.fresco_version, 1);
  EXPECT_EQ(second.camera, "b/cameras.txt");
  EXPECT_EQ(second.poses, "tcp://127.0.0.1:6001");
  EXPECT_EQ(second.time_offset_s, 0.5);
  EXPECT_TRUE(second.streams.empty());
  EXPECT_EQ(second.scene, project.scene);
  EXPECT_THROW(project.ForStream(2), std::out_of_range);
  // --set reaches into the list.
  ASSERT_TRUE(Parse(kTwoStreams, &project, {"streams.0.video=c/frames/"}).ok());
  EXPECT_EQ(project.streams[0].video, "c/frames/");
}

TEST(ProjectTest, Version1IsOneStream) {
  Project project;
  ASSERT_TRUE(Parse(WithExtra(R"("time_offset_s": 0.125)"), &project).ok());
  EXPECT_TRUE(project.streams.empty());
  EXPECT_EQ(
      project.Streams(),
      (std::vector<StreamSpec>{{"sparse/cameras.txt", "frames/", "sparse/images.txt", 0.125}}));
  EXPECT_EQ(project.StreamKey(0, "video"), "video");
  EXPECT_EQ(project.ForStream(0), project);
  EXPECT_TRUE(CheckOneStream(project, "fresco bench").ok());
}

TEST(ProjectTest, StreamsBelongToVersion2Only) {
  EXPECT_THAT(
      ParseError(WithExtra(R"("streams": [{"camera": "c.txt", "video": "f/", "poses": "i.txt"}])")),
      StartsWith("p.json: streams: needs \"fresco\": 2"));
  for (const char* key : {"camera", "video", "poses", "time_offset_s"}) {
    const std::string value = std::string(key) == "time_offset_s" ? "0" : "\"x\"";
    EXPECT_THAT(ParseError(TwoStreamsWith("\"" + std::string(key) + "\": " + value)),
                StartsWith(std::string("p.json: ") + key + ": not allowed in version 2"));
  }
  std::string missing = kTwoStreams;
  missing.erase(missing.find("\"streams\""), missing.rfind(']') - missing.find("\"streams\"") + 1);
  missing.replace(missing.rfind(','), 1, "");
  EXPECT_EQ(ParseError(missing), "p.json: streams: missing required key");
  EXPECT_EQ(ParseError(R"({"fresco": 2, "scene": "s.gltf", "streams": []})"),
            "p.json: streams: must list at least one stream");
  EXPECT_EQ(ParseError(R"({"fresco": 2, "scene": "s.gltf", "streams": {}})"),
            "p.json: streams: expected an array, got object");
}

TEST(ProjectTest, StreamKeysAreStrict) {
  std::string typo = kTwoStreams;
  typo.replace(typo.find("\"video\": \"udp"), 7, "\"vidoe\"");
  EXPECT_EQ(ParseError(typo), "p.json: streams[1].vidoe: unknown key (did you mean 'video'?)");
  std::string no_poses = kTwoStreams;
  const std::string poses = R"(, "poses": "a/images.txt")";
  no_poses.erase(no_poses.find(poses), poses.size());
  EXPECT_EQ(ParseError(no_poses), "p.json: streams[0].poses: missing required key");
  EXPECT_THAT(ParseError(kTwoStreams, {"streams.1.time_offset_s=\"late\""}),
              StartsWith("p.json: streams[1].time_offset_s: expected a number, got string"));
  EXPECT_THAT(ParseError(kTwoStreams, {"streams.0.camera=\"\""}),
              StartsWith("p.json: streams[0].camera: must not be empty"));
  EXPECT_EQ(ParseError(R"({"fresco": 2, "scene": "s.gltf", "streams": ["a"]})"),
            "p.json: streams[0]: expected an object, got string \"a\"");
}

TEST(ProjectTest, Version2SaveThenLoadGivesTheSameProject) {
  const std::string dir = testing::MakeTempDir("project");
  Project project = NonDefaultProjectV2();
  project.file_path = dir + "/project.json";
  ASSERT_TRUE(SaveProject(project, project.file_path).ok());
  const std::string text = testing::ReadText(project.file_path);
  EXPECT_THAT(text, HasSubstr("\"fresco\": 2"));
  EXPECT_THAT(text, HasSubstr("\"streams\": ["));
  EXPECT_THAT(text, Not(HasSubstr("\n  \"camera\"")));  // no top-level stream keys
  Project loaded;
  const Status status = LoadProject(project.file_path, {}, &loaded);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(loaded.streams, project.streams);
  EXPECT_EQ(loaded, project);
  // And a version-1 file writes no `streams`.
  EXPECT_THAT(ProjectToJsonText(NonDefaultProject()), Not(HasSubstr("streams")));
  // Saved elsewhere, the streams' paths still name the same files.
  fs::create_directories(dir + "/b");
  ASSERT_TRUE(SaveProject(project, dir + "/b/copy.json").ok());
  Project copy;
  ASSERT_TRUE(LoadProject(dir + "/b/copy.json", {}, &copy).ok());
  EXPECT_EQ(copy.streams[0].camera, "../a/cameras.txt");
  EXPECT_EQ(copy.streams[0].video, "../a/frames/");
  EXPECT_EQ(copy.streams[1].video, "udp://127.0.0.1:5001");
  for (size_t i = 0; i < copy.streams.size(); ++i)
    for (auto field : {&StreamSpec::camera, &StreamSpec::video, &StreamSpec::poses})
      EXPECT_EQ(copy.Resolve(copy.streams[i].*field), project.Resolve(project.streams[i].*field));
}

// ---- The settings catalogue (pipeline/core/settings.h) against the reader: every setting it
// lists is one the reader takes by --set, within the range it states and no further, and each
// has its help; what the app's widgets and `fresco settings` show is what the file means.

// The setting `key` of the project parsed with `--set KEY=VALUE`, as text; the error if any.
std::string ParsedValue(const std::string& key, const std::string& value, bool* ok) {
  Project project;
  const Status status = ParseProject(kMinimal, "p.json", {key + "=" + value}, &project);
  *ok = status.ok();
  if (!status.ok()) return status.message();
  for (const Setting& s : DescribeSettings(&project))
    if (s.key == key) return s.ValueText();
  return "(not listed)";
}

// A value inside the setting's range other than `current`.
double OtherValueInRange(const Setting& s, double current) {
  const double lo = std::isfinite(s.min) ? s.min : current - 10;
  const double hi = std::isfinite(s.max) ? s.max : std::max(lo, current) + 10;
  for (const double candidate : {current + 1, (lo + hi) / 2, hi, current * 2 + 1, lo + 1})
    if (candidate != current && candidate <= hi &&
        (candidate > lo || (!s.min_exclusive && candidate == lo)))
      return s.kind == Setting::Kind::kInt ? std::floor(candidate) : candidate;
  return current;
}

TEST(Settings, EverySettingHasHelpAndAUniqueKey) {
  Project project;
  const std::vector<Setting> settings = DescribeSettings(&project);
  EXPECT_GE(settings.size(), 60u);
  std::set<std::string> keys;
  for (const Setting& s : settings) {
    EXPECT_TRUE(keys.insert(s.key).second) << s.key;
    EXPECT_GE(s.help.size(), 10u) << s.key << ": no help";
  }
  for (const char* key : {"pipeline.sampling", "pipeline.background.window_frames",
                          "pipeline.refine.mode", "grouping.angle_deg", "live.queue_frames"})
    EXPECT_EQ(keys.count(key), 1u) << key;
}

TEST(Settings, EverySettingRoundTripsThroughSetWithinItsRangeAndNoFurther) {
  Project defaults;
  int checked = 0;
  for (const Setting& s : DescribeSettings(&defaults)) {
    bool ok = false;
    switch (s.kind) {
      case Setting::Kind::kBool: {
        const std::string flipped = *s.flag ? "false" : "true";
        EXPECT_EQ(ParsedValue(s.key, flipped, &ok), flipped) << s.key;
        break;
      }
      case Setting::Kind::kChoice:
        for (const std::string& name : s.choices)
          EXPECT_EQ(ParsedValue(s.key, "\"" + name + "\"", &ok), "`" + name + "`") << s.key;
        ParsedValue(s.key, "\"no-such-choice\"", &ok);
        EXPECT_FALSE(ok) << s.key;
        break;
      case Setting::Kind::kInt:
      case Setting::Kind::kNumber: {
        const double current = s.kind == Setting::Kind::kInt ? *s.integer : *s.number;
        const double other = OtherValueInRange(s, current);
        ASSERT_NE(other, current) << s.key;
        Project expected;
        for (const Setting& e : DescribeSettings(&expected)) {
          if (e.key != s.key) continue;
          if (e.integer) *e.integer = static_cast<int>(other);
          if (e.number) *e.number = other;
          char text[64];
          std::snprintf(text, sizeof(text), "%.17g", other);
          EXPECT_EQ(ParsedValue(s.key, text, &ok), e.ValueText()) << s.key;
          EXPECT_TRUE(ok) << s.key;
        }
        if (std::isfinite(s.max)) {  // just beyond the stated range: refused, naming the key
          const std::string beyond = std::to_string(s.max + 1);
          const std::string message = ParsedValue(s.key, beyond, &ok);
          EXPECT_FALSE(ok) << s.key << " = " << beyond;
          EXPECT_NE(message.find(s.Name()), std::string::npos) << message;
        }
        if (std::isfinite(s.min)) {
          const std::string below =
              s.min_exclusive ? std::to_string(s.min) : std::to_string(s.min - 1);
          ParsedValue(s.key, below, &ok);
          EXPECT_FALSE(ok) << s.key << " = " << below;
        }
        break;
      }
      case Setting::Kind::kText:
        break;
    }
    ++checked;
  }
  EXPECT_GE(checked, 60);
}

// A member added to a stage's settings but left out of its Fields() list would be neither read
// nor written (and no test above would see it): every byte of the pipeline's settings must be
// a listed field or padding. A byte that is neither changes operator== when flipped.
TEST(Settings, EveryMemberOfThePipelineSettingsIsListed) {
  PipelineOptions options;
  const std::vector<std::pair<size_t, size_t>> spans = ListedFieldBytes(&options);
  std::vector<bool> listed(sizeof(PipelineOptions), false);
  for (const auto& [offset, size] : spans) {
    ASSERT_LE(offset + size, sizeof(PipelineOptions));
    for (size_t i = offset; i < offset + size; ++i) listed[i] = true;
  }
  static_assert(std::is_trivially_copyable_v<PipelineOptions>);
  for (size_t i = 0; i < sizeof(PipelineOptions); ++i) {
    if (listed[i]) continue;
    PipelineOptions flipped;
    std::memcpy(static_cast<void*>(&flipped), &options, sizeof(options));
    reinterpret_cast<unsigned char*>(&flipped)[i] ^= 1;  // a bool stays a bool
    EXPECT_TRUE(flipped == options) << "byte " << i << " of PipelineOptions is a member that "
                                    << "no Fields() list names";
  }
  // The check can fail: a listed byte flipped is a different setting.
  PipelineOptions flipped = options;
  reinterpret_cast<unsigned char*>(&flipped)[spans.back().first] ^= 1;
  EXPECT_FALSE(flipped == options);
}

TEST(Settings, TableRowsShowDefaultRangeAndHelp) {
  const std::vector<std::string> rows = SettingsTableRows("pipeline.background.window_frames");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].rfind("| `pipeline.background.window_frames` | 40 | int 2 to 65535 | ", 0), 0u)
      << rows[0];
  EXPECT_EQ(SettingsTableRows("pipeline.occlusion.max_view_angle_deg")[0].rfind(
                "| `pipeline.occlusion.max_view_angle_deg` | 80 | > 0 to 90 | ", 0),
            0u);
  EXPECT_TRUE(SettingsTableRows("no.such.prefix").empty());
}

}  // namespace
}  // namespace fresco
