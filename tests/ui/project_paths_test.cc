// Repairing a project's paths in place and classifying dropped files, without an ImGui frame:
// a moved video is repaired keeping every other key of the file, a wrong path is the CLI's
// own error with nothing written, a path edit of the open project is undoable, and each kind
// of dropped file is told by its extension or content.
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/test_support.h"
#include "tests/ui/headless_ui.h"
#include "ui/core/app_state.h"
#include "ui/core/dropped_file.h"
#include "ui/core/project_paths.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using testing::Capture;
using testing::MakeTempDir;
using testing::ReadText;
using testing::WriteText;

// A copy of the capture whose project file has settings of its own and whose frames were
// moved to frames-moved/ (so the project names a folder that is gone).
std::string CopyWithMovedFrames() {
  const std::string dir = MakeTempDir("repair") + "/capture";
  fs::copy(Capture(), dir, fs::copy_options::recursive);
  nlohmann::ordered_json j = nlohmann::ordered_json::parse(ReadText(dir + "/project.json"));
  j["pipeline"] = {{"update_every", 3}, {"sampling", "area"}};
  WriteText(dir + "/project.json", j.dump(2) + "\n");
  fs::rename(dir + "/frames", dir + "/frames-moved");
  return dir;
}

// Opens `file` (which fails: a file it names is missing) and repairs its video to `video`.
Status OpenAndRepairVideo(AppState* state, const std::string& file, const std::string& video) {
  EXPECT_FALSE(state->Open(file).ok());
  ProjectPaths typed = EditablePaths(state->unopened);
  typed.video = video;
  std::string repaired_file;
  return state->RepairPaths(typed, &repaired_file);
}

nlohmann::ordered_json Json(const std::string& file) {
  return nlohmann::ordered_json::parse(ReadText(file));
}

TEST(ProjectRepair, AMovedVideoIsRepairedInPlaceKeepingEveryOtherKey) {
  const std::string dir = CopyWithMovedFrames();
  const std::string file = dir + "/project.json";
  const nlohmann::ordered_json before = Json(file);
  AppState state;
  const Status s = state.Open(file);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message(), file + ": video: " + dir + "/frames/ does not exist");
  ASSERT_TRUE(state.has_unopened);
  EXPECT_FALSE(state.has_project);
  ProjectPaths typed = EditablePaths(state.unopened);
  EXPECT_EQ(typed.video, dir + "/frames/");
  EXPECT_EQ(typed.camera, dir + "/camera.cameramodel");
  typed.video = dir + "/frames-moved/";
  std::string repaired_file;
  const Status r = state.RepairPaths(typed, &repaired_file);
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_EQ(repaired_file, file);
  EXPECT_FALSE(state.has_unopened);
  // The video key changed, relative to the file; every other key and their order did not.
  nlohmann::ordered_json after = Json(file);
  EXPECT_EQ(after["video"], "frames-moved/");
  after["video"] = before["video"];
  EXPECT_EQ(after.dump(), before.dump());
  EXPECT_EQ(after["pipeline"]["update_every"], 3);
  ASSERT_TRUE(state.Open(file).ok());
  EXPECT_EQ(state.project.video, "frames-moved/");
  EXPECT_EQ(state.project.pipeline.update_every, 3);
  for (const auto& entry : fs::directory_iterator(dir))  // no temp file left behind
    EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << entry.path();
}

TEST(ProjectRepair, AWrongPathIsTheCommandLineErrorAndNothingIsWritten) {
  const std::string dir = CopyWithMovedFrames();
  const std::string file = dir + "/project.json";
  const std::string text = ReadText(file);
  AppState state;
  const Status s = OpenAndRepairVideo(&state, file, dir + "/nowhere/");
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message(), file + ": video: 'nowhere/' does not exist (" + dir + "/nowhere/)");
  EXPECT_EQ(ReadText(file), text) << "nothing written";
  EXPECT_TRUE(state.has_unopened) << "still waiting for a repair";
  // `fresco run` stops on the same line for the same project.
  nlohmann::ordered_json j = Json(file);
  j["video"] = "nowhere/";
  WriteText(dir + "/by-hand.json", j.dump(2));
  const auto run = testing::RunFresco({"run", dir + "/by-hand.json", "--out", dir + "/out"});
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.err, "error: " + dir + "/by-hand.json: video: 'nowhere/' does not exist (" + dir +
                         "/nowhere/)\n");
  // A camera that is not a camera: the loader's error, naming the field's file.
  ProjectPaths typed = EditablePaths(state.unopened);
  typed.video = dir + "/frames-moved/";
  typed.camera = dir + "/sparse/images.txt";
  std::string repaired_file;
  EXPECT_FALSE(state.RepairPaths(typed, &repaired_file).ok());
  EXPECT_EQ(ReadText(file), text);
}

TEST(ProjectRepair, APathEditOfTheOpenProjectIsUndoableAndKeepsOtherUnsavedEdits) {
  const std::string dir = CopyWithMovedFrames();
  const std::string file = dir + "/project.json";
  fs::copy(dir + "/frames-moved", dir + "/frames", fs::copy_options::recursive);
  AppState state;
  ASSERT_TRUE(state.Open(file).ok());
  state.BeginEdit();  // an unsaved settings edit
  state.project.pipeline.update_every = 5;
  ProjectPaths typed = EditablePaths(state.project);
  typed.video = dir + "/frames-moved/";
  std::string repaired_file;
  ASSERT_TRUE(state.RepairPaths(typed, &repaired_file).ok());
  EXPECT_EQ(state.project.video, "frames-moved/");
  EXPECT_EQ(state.project.pipeline.update_every, 5) << "the unsaved edit stays";
  EXPECT_TRUE(state.dirty) << "still unsaved";
  Project on_disk;
  ASSERT_TRUE(LoadProject(file, {}, &on_disk).ok());
  EXPECT_EQ(on_disk.video, "frames-moved/");
  EXPECT_EQ(on_disk.pipeline.update_every, 3) << "only the paths were written";
  ASSERT_EQ(state.undo.size(), 2u);
  ASSERT_TRUE(state.Undo());
  EXPECT_EQ(state.project.video, "frames/");
  EXPECT_EQ(state.project.pipeline.update_every, 5);
  ASSERT_TRUE(state.Redo());
  EXPECT_EQ(state.project.video, "frames-moved/");
}

TEST(ProjectRepair, AVersionTwoFileHasItsOneStreamRepaired) {
  const std::string dir = CopyWithMovedFrames();
  const std::string file = dir + "/v2.json";
  WriteText(file,
            "{\"fresco\": 2, \"scene\": \"scene.gltf\", \"streams\": [{\"camera\": "
            "\"camera.cameramodel\", \"video\": \"frames/\", \"poses\": "
            "\"sparse/images.txt\"}]}\n");
  AppState state;
  const Status s = OpenAndRepairVideo(&state, file, dir + "/frames-moved/");
  ASSERT_TRUE(s.ok()) << s.message();
  const nlohmann::ordered_json j = Json(file);
  EXPECT_EQ(j["streams"][0]["video"], "frames-moved/");
  EXPECT_EQ(j["fresco"], 2);
  EXPECT_FALSE(j.contains("video"));
  EXPECT_TRUE(state.Open(file).ok());
}

TEST(DroppedFile, EachKindIsToldByItsExtensionOrContent) {
  const std::string dir = MakeTempDir("dropped");
  auto make = [&](const std::string& name, const std::string& text) {
    WriteText(dir + "/" + name, text);
    return dir + "/" + name;
  };
  fs::create_directories(dir + "/frames");
  const std::pair<std::string, DroppedKind> cases[] = {
      {make("room.gltf", "{}"), DroppedKind::kScene},
      {make("room.GLB", "x"), DroppedKind::kScene},
      {make("scan.ply", "ply"), DroppedKind::kScene},
      {make("scan.obj", "v 0 0 0"), DroppedKind::kScene},
      {make("clip.mp4", "x"), DroppedKind::kVideo},
      {make("clip.MOV", "x"), DroppedKind::kVideo},
      {dir + "/frames", DroppedKind::kVideo},
      {make("cam.cameramodel", "{}"), DroppedKind::kCamera},
      {make("intrinsics.txt",
            "# Camera list with one line of data per camera:\n1 PINHOLE 4 3 "
            "2 2 2 1.5\n"),
       DroppedKind::kCamera},
      {make("cams.txt", "1 OPENCV 640 480 500 500 320 240 0 0 0 0\n"), DroppedKind::kCamera},
      {make("views.txt", "# Image list with two lines of data per image:\n"), DroppedKind::kPoses},
      {make("images2.txt", "1 1 0 0 0 0 0 0 1 f0.png\n\n"), DroppedKind::kPoses},
      {make("traj.txt", "# timestamp tx ty tz qx qy qz qw\n0.0 1 2 3 0 0 0 1\n"),
       DroppedKind::kPoses},
      {make("run.tum", "0 0 0 0 0 0 0 1\n"), DroppedKind::kPoses},
      {make("p.json", "{\"fresco\": 1, \"scene\": \"s.gltf\"}"), DroppedKind::kProject},
  };
  for (const auto& [path, kind] : cases) {
    const DroppedFile file = ClassifyDroppedPath(path);
    EXPECT_EQ(DroppedKindName(file.kind), std::string(DroppedKindName(kind))) << path;
    EXPECT_EQ(file.why, "") << path;
  }
  EXPECT_EQ(ClassifyDroppedPath(dir + "/frames").path, dir + "/frames/") << "a folder ends in /";
  EXPECT_EQ(ClassifyDroppedPath(dir + "/frames/").path, dir + "/frames/");
}

TEST(DroppedFile, AnythingElseIsOneLineNamingTheFile) {
  const std::string dir = MakeTempDir("dropped");
  WriteText(dir + "/notes.md", "# notes\n");
  WriteText(dir + "/settings.json", "{\"pipeline\": {}}");
  WriteText(dir + "/broken.json", "{\"fresco\": ");
  WriteText(dir + "/list.json", "[1, 2]");
  WriteText(dir + "/prose.txt", "hello there, this is text\n");
  for (const std::string name :
       {"notes.md", "settings.json", "broken.json", "list.json", "prose.txt", "missing.gltf"}) {
    const DroppedFile file = ClassifyDroppedPath(dir + "/" + name);
    EXPECT_EQ(file.kind, DroppedKind::kUnknown) << name;
    EXPECT_EQ(file.why.rfind(dir + "/" + name + ": dropped, but ", 0), 0u) << file.why;
    EXPECT_EQ(file.why.find('\n'), std::string::npos) << file.why;
  }
  EXPECT_EQ(ClassifyDroppedPath(dir + "/missing.gltf").why,
            dir + "/missing.gltf: dropped, but it does not exist");
  EXPECT_EQ(ClassifyDroppedPath(dir + "/settings.json").why,
            dir + "/settings.json: dropped, but it is not a Fresco project (no \"fresco\" key)");
}

}  // namespace
}  // namespace fresco
