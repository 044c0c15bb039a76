// The `fresco` command line as users and outside checks drive it (docs/contract.md): the
// dispatcher, --help on every verb, `fresco run` end to end on a small synthetic capture,
// and bad input: exit 2, one line naming the file, and earlier outputs left as they were.
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "tests/test_support.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using testing::MakeTempDir;
using testing::ReadText;
using testing::RunFresco;
using testing::StartFresco;
using testing::WaitFresco;
using testing::WriteText;

// The lines of stderr that report an error (progress lines may come before them).
std::vector<std::string> ErrorLines(const std::string& err) {
  std::vector<std::string> lines;
  size_t start = 0;
  while (start < err.size()) {
    const size_t end = std::min(err.find('\n', start), err.size());
    const std::string line = err.substr(start, end - start);
    if (line.rfind("error: ", 0) == 0) lines.push_back(line);
    start = end + 1;
  }
  return lines;
}

TEST(Cli, DispatcherUsageAndUnknownVerb) {
  const auto none = RunFresco({});
  EXPECT_EQ(none.exit_code, 2);
  EXPECT_NE(none.err.find("usage: fresco VERB"), std::string::npos) << none.err;
  const auto unknown = RunFresco({"paint"});
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.err.find("unknown verb 'paint'"), std::string::npos) << unknown.err;
  const auto help = RunFresco({"--help"});
  EXPECT_EQ(help.exit_code, 0);
  for (const char* verb : {"run", "render", "synth", "calib", "poses", "bench", "gui"})
    EXPECT_NE(help.out.find(verb), std::string::npos) << verb;
  const auto version = RunFresco({"--version"});
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_EQ(version.out.rfind("fresco ", 0), 0u) << version.out;
  EXPECT_TRUE(std::isdigit(static_cast<unsigned char>(version.out[7]))) << version.out;
}

TEST(Cli, EveryVerbTakesHelp) {
  for (const char* verb : {"run", "render", "synth", "group", "calib", "poses", "bench", "gui"}) {
    const auto r = RunFresco({verb, "--help"});
    EXPECT_EQ(r.exit_code, 0) << verb << ": " << r.err;
    EXPECT_NE(r.out.find(std::string("fresco ") + verb), std::string::npos)
        << verb << ": " << r.out;
  }
  const auto bad_option = RunFresco({"run", "p.json", "--out", "x", "--bogus"});
  EXPECT_EQ(bad_option.exit_code, 2);
  EXPECT_NE(bad_option.err.find("--bogus"), std::string::npos) << bad_option.err;
}

// A small capture (12 frames, 160x120) made once for the tests below.
class RunCommandTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    capture_ = new std::string(MakeTempDir("run-cli") + "/capture");
    const auto r = RunFresco({"synth", "--scene", "builtin:cube-room", "--out", *capture_,
                              "--frames", "12", "--size", "160x120", "--seed", "2"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static void TearDownTestSuite() { delete capture_; }
  static std::string Project() { return *capture_ + "/project.json"; }
  // A copy of the capture to break.
  static std::string CopyCapture(const std::string& tag) {
    const std::string dir = MakeTempDir(tag) + "/capture";
    fs::copy(*capture_, dir, fs::copy_options::recursive);
    return dir;
  }
  static std::string* capture_;
};
std::string* RunCommandTest::capture_ = nullptr;

TEST_F(RunCommandTest, WritesThePaintedModelMetricsAndStageImages) {
  const std::string out = MakeTempDir("run-out") + "/out";
  const auto r = RunFresco(
      {"run", Project(), "--out", out, "--set", "pipeline.sampling=nearest", "--debug-images"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(fs::is_regular_file(out + "/painted.gltf"));
  ASSERT_TRUE(fs::is_regular_file(out + "/metrics.json"));
  const nlohmann::json m = nlohmann::json::parse(ReadText(out + "/metrics.json"));
  EXPECT_EQ(m["frames"], 12);
  EXPECT_EQ(m["frames_painted"], 12);
  EXPECT_GT(m["seconds"].get<double>(), 0.0);
  EXPECT_GT(m["fps"].get<double>(), 0.0);
  for (const char* stage : {"depth", "warp", "paint"})
    EXPECT_TRUE(m["stage_ms"].contains(stage)) << stage;
  EXPECT_EQ(m["base_buffers"], 6);  // one per face of the room
  EXPECT_GT(m["texels"].get<long long>(), 10000);
  EXPECT_GT(m["coverage"].get<double>(), 0.2);
  EXPECT_LE(m["coverage"].get<double>(), 1.0);
  // Textures: the buffers packed into one atlas page (a PNG), alpha 0 where never painted
  // and 255 where painted.
  int textures = 0, transparent = 0, opaque = 0;
  for (const auto& entry : fs::directory_iterator(out)) {
    if (entry.path().extension() != ".png" ||
        entry.path().filename().string().rfind("painted", 0) != 0)
      continue;
    ++textures;
    const cv::Mat rgba = cv::imread(entry.path().string(), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(rgba.type(), CV_8UC4) << entry.path();
    for (int y = 0; y < rgba.rows; ++y)
      for (int x = 0; x < rgba.cols; ++x) {
        const uchar a = rgba.at<cv::Vec4b>(y, x)[3];
        transparent += a == 0, opaque += a == 255;
      }
  }
  EXPECT_EQ(textures, 1);
  EXPECT_EQ(m["atlas"]["pages"], 1);
  EXPECT_GT(m["atlas"]["occupancy"].get<double>(), 0.5);
  // Nothing staged is left behind.
  for (const auto& entry : fs::directory_iterator(out))
    EXPECT_NE(entry.path().filename().string()[0], '.') << entry.path();
  EXPECT_GT(transparent, 0);
  EXPECT_GT(opaque, 0);
  // Per-stage debug images were asked for.
  int stage_images = 0;
  for (const auto& entry : fs::directory_iterator(out + "/stages"))
    stage_images += entry.is_regular_file();
  EXPECT_GT(stage_images, 12);
  // The painted model renders through the capture's camera.
  const auto render =
      RunFresco({"render", out + "/painted.gltf", "--camera", *capture_ + "/camera.cameramodel",
                 "--poses", *capture_ + "/sparse/images.txt", "--out", out + "/renders"});
  EXPECT_EQ(render.exit_code, 0) << render.err;
  EXPECT_TRUE(fs::is_regular_file(out + "/renders/000005.png"));
}

TEST_F(RunCommandTest, SetOverridesAndUpdateEvery) {
  const std::string out = MakeTempDir("run-every") + "/out";
  const auto r =
      RunFresco({"run", Project(), "--out", out, "--set", "pipeline.update_every=4", "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;  // --quiet
  const nlohmann::json m = nlohmann::json::parse(ReadText(out + "/metrics.json"));
  EXPECT_EQ(m["frames"], 12);
  EXPECT_EQ(m["frames_painted"], 3);
}

// The grouping is data: shown by `fresco group`, stored with --save as explicit groups,
// edited in the project, and honoured by `fresco run`.
TEST_F(RunCommandTest, GroupingIsStoredEditedAndHonoured) {
  const std::string dir = CopyCapture("run-group");
  const std::string project = dir + "/project.json";
  const auto shown = RunFresco({"group", project, "--json", dir + "/groups.json"});
  ASSERT_EQ(shown.exit_code, 0) << shown.err;
  EXPECT_NE(shown.out.find("6 base buffers for 12 triangles"), std::string::npos) << shown.out;
  const nlohmann::json table = nlohmann::json::parse(ReadText(dir + "/groups.json"));
  EXPECT_EQ(table["groups"].size(), 6u);
  // The paper's grouping (no chart stretch bound) at 100 degrees: neighbouring faces (90
  // degrees apart) join a group, but no single projection serves a corner: the groups are
  // split again, and that is reported.
  const auto coarse = RunFresco({"group", project, "--set", "grouping.angle_deg=100", "--set",
                                 "grouping.min_chart_texels=0"});
  EXPECT_EQ(coarse.exit_code, 0) << coarse.err;
  EXPECT_NE(coarse.out.find("6 base buffers"), std::string::npos) << coarse.out;
  EXPECT_EQ(coarse.out.find("; 0 groups split"), std::string::npos) << coarse.out;

  ASSERT_EQ(RunFresco({"group", project, "--save"}).exit_code, 0);
  const nlohmann::json saved = nlohmann::json::parse(ReadText(project));
  ASSERT_EQ(saved["grouping"]["groups"].size(), 6u);
  // Stored groups are used as they are: the angle no longer matters.
  const std::string out = dir + "/out";
  ASSERT_EQ(RunFresco({"run", project, "--out", out, "--quiet", "--set", "grouping.angle_deg=100"})
                .exit_code,
            0);
  EXPECT_EQ(nlohmann::json::parse(ReadText(out + "/metrics.json"))["base_buffers"], 6);
  // Edits on top of the stored groups: group 2 gets its own texel size.
  const auto edited =
      RunFresco({"run", project, "--out", out, "--quiet", "--set",
                 R"(grouping.edits=[{"op": "texel", "groups": [2], "texel_size_m": 0.05}])"});
  ASSERT_EQ(edited.exit_code, 0) << edited.err;
  const nlohmann::json m = nlohmann::json::parse(ReadText(out + "/metrics.json"));
  int coarse_buffers = 0;
  for (const auto& b : m["buffers"])
    coarse_buffers += std::abs(b["texel_size_m"].get<double>() - 0.05) < 1e-9;
  EXPECT_EQ(coarse_buffers, 1);
  // A stored group naming a triangle the scene does not have: exit 2, naming the field.
  const auto bad = RunFresco({"run", project, "--out", out, "--quiet", "--set",
                              R"(grouping.groups=[{"triangles": [0, 99]}])"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("grouping.groups[0]: triangle 99"), std::string::npos) << bad.err;
}

// Bad input: exit 2, a one-line message naming the file (and field), and an output folder
// from an earlier good run left exactly as it was.
// Out of memory (here: 0.5 mm texels on a room, several GB, in a 700 MB address space) is a
// one-line message saying what needs less, exit 1, and the earlier outputs kept; never an
// abort.
TEST_F(RunCommandTest, OutOfMemoryExits1WithOneLineAndKeepsEarlierOutputs) {
  const std::string out = MakeTempDir("run-oom") + "/out";
  ASSERT_EQ(RunFresco({"run", Project(), "--out", out, "--quiet"}).exit_code, 0);
  const std::string metrics_before = ReadText(out + "/metrics.json");
  const std::string gltf_before = ReadText(out + "/painted.gltf");
  const auto r = WaitFresco(StartFresco({"run", Project(), "--out", out, "--quiet", "--set",
                                         "pipeline.texel_size_m=0.0005", "--set",
                                         "pipeline.max_buffer_texels=2000000000"},
                                        700LL << 20));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("fresco run: out of memory"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("pipeline.texel_size_m"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(ReadText(out + "/metrics.json"), metrics_before);
  EXPECT_EQ(ReadText(out + "/painted.gltf"), gltf_before);
}

TEST_F(RunCommandTest, BadInputExits2NamingTheFileAndKeepsEarlierOutputs) {
  const std::string out = MakeTempDir("run-bad") + "/out";
  ASSERT_EQ(RunFresco({"run", Project(), "--out", out, "--quiet"}).exit_code, 0);
  const std::string metrics_before = ReadText(out + "/metrics.json");
  const std::string gltf_before = ReadText(out + "/painted.gltf");

  struct Case {
    std::string what;
    std::vector<std::string> args;
    std::string expect;  // in the message
  };
  std::vector<Case> cases;
  cases.push_back(
      {"missing project", {"run", "/no/such/project.json", "--out", out}, "/no/such/project.json"});
  {
    const std::string dir = MakeTempDir("run-json");
    WriteText(dir + "/project.json", "{\"fresco\": 1, \"scene\": ");
    cases.push_back(
        {"malformed JSON", {"run", dir + "/project.json", "--out", out}, "project.json"});
  }
  cases.push_back({"unknown key by --set",
                   {"run", Project(), "--out", out, "--set", "pipeline.samplng=nearest"},
                   "pipeline.samplng"});
  cases.push_back({"wrong type by --set",
                   {"run", Project(), "--out", out, "--set", "pipeline.update_every=\"often\""},
                   "pipeline.update_every"});
  {
    const std::string dir = CopyCapture("run-nan");
    std::string images = ReadText(dir + "/sparse/images.txt");
    const size_t line = images.find("\n1 ");  // first image line: IMAGE_ID QW ...
    ASSERT_NE(line, std::string::npos);
    const size_t qw = line + 3;
    images.replace(qw, images.find(' ', qw) - qw, "nan");
    WriteText(dir + "/sparse/images.txt", images);
    cases.push_back({"NaN in a pose", {"run", dir + "/project.json", "--out", out}, "images.txt"});
  }
  {
    const std::string dir = CopyCapture("run-missing-frame");
    fs::remove(dir + "/frames/000003.png");
    cases.push_back({"frame listed in poses but missing",
                     {"run", dir + "/project.json", "--out", out},
                     "000003"});
  }
  {
    const std::string dir = CopyCapture("run-corrupt-frame");
    WriteText(dir + "/frames/000005.png", "this is not a PNG");
    cases.push_back({"corrupt frame", {"run", dir + "/project.json", "--out", out}, "000005.png"});
  }
  {
    const std::string dir = CopyCapture("run-frame-size");
    cv::imwrite(dir + "/frames/000007.png", cv::Mat(60, 80, CV_8UC3, cv::Scalar(1, 2, 3)));
    cases.push_back(
        {"frame of the wrong size", {"run", dir + "/project.json", "--out", out}, "000007.png"});
  }
  {
    const std::string dir = CopyCapture("run-missing-scene");
    fs::remove(dir + "/scene.gltf");
    cases.push_back({"missing scene", {"run", dir + "/project.json", "--out", out}, "scene.gltf"});
  }
  for (const Case& c : cases) {
    const auto r = RunFresco(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.what << ": " << r.err;
    const std::vector<std::string> errors = ErrorLines(r.err);
    ASSERT_EQ(errors.size(), 1u) << c.what << ": " << r.err;
    EXPECT_NE(errors[0].find(c.expect), std::string::npos) << c.what << ": " << r.err;
    EXPECT_EQ(ReadText(out + "/metrics.json"), metrics_before) << c.what;
    EXPECT_EQ(ReadText(out + "/painted.gltf"), gltf_before) << c.what;
  }
}

// A version-2 project: the capture split into two streams (even frames in a/, odd frames in
// b/, each with its own copy of the camera and its own poses). Interleaved by frame index
// the two streams bring the frames in the capture's own order, so the one model is painted
// as the version-1 project paints it.
class StreamsTest : public RunCommandTest {
 protected:
  // Writes DIR/{a,b}/{frames/,camera.cameramodel,images.txt} and DIR/streams.json.
  static std::string SplitIntoTwoStreams(const std::string& dir) {
    std::vector<fs::path> frames;
    for (const auto& entry : fs::directory_iterator(dir + "/frames")) frames.push_back(entry);
    std::sort(frames.begin(), frames.end());
    for (const char* s : {"a", "b"}) {
      fs::create_directories(dir + "/" + s + "/frames");
      fs::copy_file(dir + "/camera.cameramodel", dir + "/" + s + "/camera.cameramodel");
    }
    std::map<std::string, std::string> stream_of;  // frame name -> "a" | "b"
    for (size_t i = 0; i < frames.size(); ++i) {
      const std::string stream = i % 2 == 0 ? "a" : "b";
      stream_of[frames[i].filename().string()] = stream;
      fs::rename(frames[i], dir + "/" + stream + "/frames/" + frames[i].filename().string());
    }
    // images.txt: comment lines, then per image a pose line (NAME last) and a points line.
    std::map<std::string, std::string> images = {{"a", ""}, {"b", ""}};
    std::istringstream in(ReadText(dir + "/sparse/images.txt"));
    std::string line, stream;
    for (bool pose_line = true; std::getline(in, line);) {
      if (!line.empty() && line[0] == '#') continue;
      if (pose_line) stream = stream_of.at(line.substr(line.rfind(' ') + 1));
      images[stream] += line + "\n";
      pose_line = !pose_line;
    }
    for (const auto& [s, text] : images) WriteText(dir + "/" + s + "/images.txt", text);
    const std::string project = dir + "/streams.json";
    WriteText(project, R"({"fresco": 2, "scene": "scene.gltf", "streams": [
      {"camera": "a/camera.cameramodel", "video": "a/frames/", "poses": "a/images.txt"},
      {"camera": "b/camera.cameramodel", "video": "b/frames/", "poses": "b/images.txt",
       "time_offset_s": 0}]})");
    return project;
  }
};

TEST_F(StreamsTest, TwoStreamsPaintTheModelAsOneDoes) {
  const std::string dir = CopyCapture("run-streams");
  const std::string project = SplitIntoTwoStreams(dir);
  const auto one = RunFresco({"run", Project(), "--out", dir + "/one", "--quiet"});
  ASSERT_EQ(one.exit_code, 0) << one.err;
  const auto two = RunFresco({"run", project, "--out", dir + "/two", "--quiet"});
  ASSERT_EQ(two.exit_code, 0) << two.err;
  const nlohmann::json m1 = nlohmann::json::parse(ReadText(dir + "/one/metrics.json"));
  const nlohmann::json m2 = nlohmann::json::parse(ReadText(dir + "/two/metrics.json"));
  EXPECT_EQ(m2["frames"], 12);
  EXPECT_EQ(m2["frames_painted"], 12);
  EXPECT_EQ(m2["base_buffers"], m1["base_buffers"]);
  for (const char* stage : {"depth", "warp", "paint"})
    EXPECT_TRUE(m2["stage_ms"].contains(stage)) << stage;
  // The automatic texel size looks at both streams' poses: about the same as for all frames.
  EXPECT_NEAR(m2["texel_size_m"].get<double>(), m1["texel_size_m"].get<double>(),
              0.05 * m1["texel_size_m"].get<double>());
  EXPECT_GT(m1["coverage"].get<double>(), 0.2);
  EXPECT_NEAR(m2["coverage"].get<double>(), m1["coverage"].get<double>(), 0.01);
  ASSERT_EQ(m1["streams"].size(), 1u);
  EXPECT_EQ(m1["streams"][0]["frames"], 12);
  ASSERT_EQ(m2["streams"].size(), 2u);
  for (int s = 0; s < 2; ++s) {
    EXPECT_EQ(m2["streams"][s]["video"], s == 0 ? "a/frames/" : "b/frames/");
    EXPECT_EQ(m2["streams"][s]["frames"], 6) << s;
    EXPECT_EQ(m2["streams"][s]["frames_painted"], 6) << s;
  }
  // Interleaved by frame index: the first 5 frames are 3 of a's and 2 of b's.
  const auto first = RunFresco(
      {"run", project, "--out", dir + "/first", "--quiet", "--set", "pipeline.max_frames=5"});
  ASSERT_EQ(first.exit_code, 0) << first.err;
  const nlohmann::json m3 = nlohmann::json::parse(ReadText(dir + "/first/metrics.json"));
  EXPECT_EQ(m3["frames"], 5);
  EXPECT_EQ(m3["streams"][0]["frames"], 3);
  EXPECT_EQ(m3["streams"][1]["frames"], 2);
  // `fresco group` reads every stream too.
  const auto group = RunFresco({"group", project});
  EXPECT_EQ(group.exit_code, 0) << group.err;
  EXPECT_NE(group.out.find("6 base buffers"), std::string::npos) << group.out;
}

TEST_F(StreamsTest, BadStreamsExit2NamingTheStream) {
  const std::string dir = CopyCapture("run-streams-bad");
  const std::string project = SplitIntoTwoStreams(dir);
  const std::string out = dir + "/out";
  struct Case {
    std::string what;
    std::vector<std::string> args;
    std::vector<std::string> expect;  // in the message
  };
  std::vector<Case> cases;
  cases.push_back({"unknown stream key",
                   {"run", project, "--out", out, "--set", "streams.1.vidoe=b/frames/"},
                   {"streams.json", "streams[1].vidoe", "unknown key"}});
  cases.push_back({"top-level camera in version 2",
                   {"run", project, "--out", out, "--set", "camera=a/camera.cameramodel"},
                   {"streams.json", "camera: not allowed in version 2"}});
  cases.push_back({"live video among several streams, poses without times",
                   {"run", project, "--out", out, "--set", "streams.1.video=udp://127.0.0.1:5999"},
                   {"streams.json: streams[1]: ", "b/images.txt", "matched to poses by time"}});
  cases.push_back({"recording several streams",
                   {"run", project, "--out", out, "--set", "streams.1.video=udp://127.0.0.1:5999",
                    "--record", out + "/recorded"},
                   {"streams.json: streams: --record records a project with one stream",
                    "(this one has 2)"}});
  cases.push_back({"bench reads one stream",
                   {"bench", project, "--out", out},
                   {"streams.json", "streams: 2 video streams", "fresco bench"}});
  {
    const std::string broken = CopyCapture("run-streams-missing");
    const std::string broken_project = SplitIntoTwoStreams(broken);
    fs::remove_all(broken + "/b/frames");
    cases.push_back({"missing video folder",
                     {"run", broken_project, "--out", out},
                     {"streams.json", "streams[1].video", "b/frames/"}});
  }
  {
    const std::string broken = CopyCapture("run-streams-size");
    const std::string broken_project = SplitIntoTwoStreams(broken);
    cv::imwrite(broken + "/b/frames/000007.png", cv::Mat(60, 80, CV_8UC3, cv::Scalar(1, 2, 3)));
    cases.push_back({"frame of the wrong size in stream b",
                     {"run", broken_project, "--out", out},
                     {"b/frames", "000007.png"}});
  }
  for (const Case& c : cases) {
    const auto r = RunFresco(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.what << ": " << r.err;
    const std::vector<std::string> errors = ErrorLines(r.err);
    ASSERT_EQ(errors.size(), 1u) << c.what << ": " << r.err;
    for (const std::string& expect : c.expect)
      EXPECT_NE(errors[0].find(expect), std::string::npos) << c.what << ": " << r.err;
    EXPECT_FALSE(fs::exists(out + "/metrics.json")) << c.what;
  }
}

}  // namespace
}  // namespace fresco
