// Corrupt inputs end to end (README "Reliability"): `fresco run` on a project whose files are
// broken one way at a time exits 2 with one line on stderr that names the broken file and says what
// is wrong, and leaves the output folder of an earlier good run exactly as it was. Each case has
// its own test (the README's reliability table names them).
#include <cstring>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "tests/test_support.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using testing::CommandResult;
using testing::MakeTempDir;
using testing::ReadText;
using testing::RunFresco;
using testing::WriteText;

// A good capture (12 frames, 160x120), and an output folder holding earlier outputs.
class CorruptInputTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const std::string root = MakeTempDir("corrupt");
    capture_ = new std::string(root + "/capture");
    out_ = new std::string(root + "/out");
    const CommandResult synth =
        RunFresco({"synth", "--scene", "builtin:cube-room", "--out", *capture_, "--frames", "12",
                   "--size", "160x120", "--seed", "4"});
    ASSERT_EQ(synth.exit_code, 0) << synth.err;
    // Stand-ins for an earlier run's outputs (fresco never reads them; they must stay).
    WriteText(*out_ + "/metrics.json", "{\"earlier\": \"run\"}\n");
    WriteText(*out_ + "/painted.gltf", "{\"asset\": {\"version\": \"2.0\"}}\n");
  }
  static void TearDownTestSuite() {
    delete capture_;
    delete out_;
  }
  // A copy of the good capture to break.
  static std::string Copy(const std::string& tag) {
    const std::string dir = MakeTempDir(tag) + "/capture";
    fs::copy(*capture_, dir, fs::copy_options::recursive);
    return dir;
  }
  // Sets project keys (e.g. {"video": "video.avi"}) in DIR/project.json.
  static void SetProject(const std::string& dir, const nlohmann::json& keys) {
    nlohmann::json project = nlohmann::json::parse(ReadText(dir + "/project.json"));
    project.update(keys);
    WriteText(dir + "/project.json", project.dump(2));
  }
  // `fresco run DIR/project.json --out OUT` must exit 2 with one stderr line that holds
  // every one of `expected`; the earlier good outputs must be untouched. Returns the line.
  static std::string ExpectBadInput(const std::string& dir,
                                    const std::vector<std::string>& expected) {
    const std::string metrics = ReadText(*out_ + "/metrics.json");
    const std::string gltf = ReadText(*out_ + "/painted.gltf");
    const CommandResult r = RunFresco({"run", dir + "/project.json", "--out", *out_, "--quiet"});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    std::string line = r.err;
    if (!line.empty() && line.back() == '\n') line.pop_back();
    EXPECT_EQ(line.find('\n'), std::string::npos) << "more than one line: " << r.err;
    EXPECT_EQ(line.rfind("error: ", 0), 0u) << line;
    for (const std::string& e : expected)
      EXPECT_NE(line.find(e), std::string::npos) << "'" << e << "' not in: " << line;
    EXPECT_EQ(ReadText(*out_ + "/metrics.json"), metrics);
    EXPECT_EQ(ReadText(*out_ + "/painted.gltf"), gltf);
    std::printf("%s\n", line.c_str());  // the README's table quotes these
    return line;
  }
  // The capture's frames as an MJPG AVI (frame names "%06d.png" match the poses).
  static void WriteVideo(const std::string& dir, const std::string& path) {
    cv::VideoWriter writer(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10,
                           cv::Size(160, 120));
    ASSERT_TRUE(writer.isOpened());
    for (int i = 0; i < 12; ++i) {
      char name[32];
      std::snprintf(name, sizeof name, "/frames/%06d.png", i);
      writer.write(cv::imread(dir + name, cv::IMREAD_COLOR));
    }
  }
  static std::string* capture_;
  static std::string* out_;
};
std::string* CorruptInputTest::capture_ = nullptr;
std::string* CorruptInputTest::out_ = nullptr;

TEST_F(CorruptInputTest, TruncatedVideoFile) {
  const std::string dir = Copy("truncated-video");
  WriteVideo(dir, dir + "/video.avi");
  SetProject(dir, {{"video", "video.avi"}});
  // The whole video paints every frame...
  const std::string good_out = MakeTempDir("video-out");
  const CommandResult good = RunFresco({"run", dir + "/project.json", "--out", good_out});
  ASSERT_EQ(good.exit_code, 0) << good.err;
  EXPECT_EQ(nlohmann::json::parse(ReadText(good_out + "/metrics.json"))["frames_painted"], 12);
  // ... half of it is an error, not a shorter run.
  fs::resize_file(dir + "/video.avi", fs::file_size(dir + "/video.avi") / 2);
  ExpectBadInput(
      dir, {dir + "/video.avi", "of the 12 frames its header declares", "truncated or corrupt"});
}

TEST_F(CorruptInputTest, VideoFileThatIsNotAVideo) {
  const std::string dir = Copy("not-a-video");
  WriteText(dir + "/video.mp4", std::string(4096, 'x'));
  SetProject(dir, {{"video", "video.mp4"}});
  ExpectBadInput(dir, {dir + "/video.mp4", "cannot open as a video"});
}

TEST_F(CorruptInputTest, FrameOfTheWrongSize) {
  const std::string dir = Copy("frame-size");
  cv::imwrite(dir + "/frames/000007.png", cv::Mat(60, 80, CV_8UC3, cv::Scalar(1, 2, 3)));
  ExpectBadInput(dir, {"000007.png", "80x60"});
}

TEST_F(CorruptInputTest, FrameThatFailsToDecode) {
  const std::string dir = Copy("frame-decode");
  WriteText(dir + "/frames/000005.png", "this is not a PNG");
  ExpectBadInput(dir, {dir + "/frames/000005.png"});
}

TEST_F(CorruptInputTest, TruncatedFrame) {
  const std::string dir = Copy("frame-truncated");
  const std::string frame = dir + "/frames/000004.png";
  fs::resize_file(frame, fs::file_size(frame) / 2);
  ExpectBadInput(dir, {frame, "truncated PNG"});
}

// JPEG frames, one cut short (libjpeg would decode it, grey where the data stopped).
TEST_F(CorruptInputTest, TruncatedJpegFrame) {
  const std::string dir = Copy("jpeg-truncated");
  for (int i = 0; i < 12; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "/frames/%06d", i);
    const std::string png = dir + name + ".png";
    ASSERT_TRUE(cv::imwrite(dir + name + ".jpg", cv::imread(png, cv::IMREAD_COLOR)));
    fs::remove(png);
  }
  std::string images = ReadText(dir + "/sparse/images.txt");
  for (size_t at = images.find(".png"); at != std::string::npos; at = images.find(".png", at))
    images.replace(at, 4, ".jpg");
  WriteText(dir + "/sparse/images.txt", images);
  const std::string frame = dir + "/frames/000006.jpg";
  fs::resize_file(frame, fs::file_size(frame) * 2 / 3);
  ExpectBadInput(dir, {frame, "truncated JPEG"});
}

TEST_F(CorruptInputTest, EmptyVideoFolder) {
  const std::string dir = Copy("frames-empty");
  fs::remove_all(dir + "/frames");
  fs::create_directories(dir + "/frames");
  ExpectBadInput(dir, {dir + "/frames", "no image frames"});
}

TEST_F(CorruptInputTest, ColmapPoseWithNaN) {
  const std::string dir = Copy("pose-nan");
  std::string images = ReadText(dir + "/sparse/images.txt");
  const size_t line = images.find("\n3 ");  // IMAGE_ID QW QX ...
  ASSERT_NE(line, std::string::npos);
  const size_t qx = images.find(' ', line + 3) + 1;
  images.replace(qx, images.find(' ', qx) - qx, "nan");
  WriteText(dir + "/sparse/images.txt", images);
  ExpectBadInput(dir, {dir + "/sparse/images.txt", "QX"});
}

TEST_F(CorruptInputTest, TumPoseWithNaN) {
  const std::string dir = Copy("tum-nan");
  std::string tum;
  for (int i = 0; i < 12; ++i)
    tum += std::to_string(i * 0.1) + (i == 6 ? " 0 1.5 nan" : " 0 1.5 0") + " 0 0 0 1\n";
  WriteText(dir + "/poses.tum", tum);
  SetProject(dir, {{"poses", "poses.tum"}});
  ExpectBadInput(dir, {dir + "/poses.tum:7:", "not finite"});
}

TEST_F(CorruptInputTest, PoseLineWithTooFewFields) {
  const std::string dir = Copy("pose-fields");
  std::string images = ReadText(dir + "/sparse/images.txt");
  const size_t line = images.find("\n2 ");
  ASSERT_NE(line, std::string::npos);
  images.erase(line + 1, images.find('\n', line + 1) - line - 1);
  images.insert(line + 1, "2 1 0 0 0 1");
  WriteText(dir + "/sparse/images.txt", images);
  ExpectBadInput(dir, {dir + "/sparse/images.txt"});
}

// A one-triangle glTF whose indices point past its 3 vertices.
TEST_F(CorruptInputTest, GltfIndexOutOfRange) {
  const std::string dir = Copy("gltf-index");
  std::string bin(48, '\0');
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const uint16_t indices[3] = {0, 1, 7};
  std::memcpy(bin.data(), positions, sizeof positions);
  std::memcpy(bin.data() + 36, indices, sizeof indices);
  WriteText(dir + "/bad.bin", bin);
  const nlohmann::json gltf = {
      {"asset", {{"version", "2.0"}}},
      {"buffers", {{{"uri", "bad.bin"}, {"byteLength", 48}}}},
      {"bufferViews",
       {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 36}},
        {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 6}}}},
      {"accessors",
       {{{"bufferView", 0},
         {"componentType", 5126},
         {"count", 3},
         {"type", "VEC3"},
         {"min", {0, 0, 0}},
         {"max", {1, 1, 0}}},
        {{"bufferView", 1}, {"componentType", 5123}, {"count", 3}, {"type", "SCALAR"}}}},
      {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
      {"nodes", {{{"mesh", 0}}}},
      {"scenes", {{{"nodes", {0}}}}},
      {"scene", 0}};
  WriteText(dir + "/bad.gltf", gltf.dump(1));
  SetProject(dir, {{"scene", "bad.gltf"}});
  ExpectBadInput(dir, {dir + "/bad.gltf", "index 7 out of range (3 vertices)"});
}

TEST_F(CorruptInputTest, GltfBufferTruncated) {
  const std::string dir = Copy("gltf-bin");
  fs::resize_file(dir + "/scene.bin", fs::file_size(dir + "/scene.bin") / 2);
  ExpectBadInput(dir, {dir + "/scene.gltf"});
}

TEST_F(CorruptInputTest, CameraModelThatIsNotOne) {
  const std::string dir = Copy("camera-garbage");
  WriteText(dir + "/camera.cameramodel", "{ 'lensmodel': 'LENSMODEL_OPENCV4', 'intrinsics': [1,2");
  ExpectBadInput(dir, {dir + "/camera.cameramodel"});
}

TEST_F(CorruptInputTest, ProjectPointingAtMissingFiles) {
  for (const char* key : {"scene", "camera", "video", "poses"}) {
    const std::string dir = Copy(std::string("missing-") + key);
    SetProject(dir, {{key, std::string("no-such-") + key}});
    ExpectBadInput(dir, {key, dir + "/no-such-" + key});
  }
}

TEST_F(CorruptInputTest, ProjectThatIsNotJson) {
  const std::string dir = Copy("project-json");
  WriteText(dir + "/project.json", "{\"fresco\": 1, \"scene\": \"scene.gltf\",");
  ExpectBadInput(dir, {dir + "/project.json"});
}

}  // namespace
}  // namespace fresco
