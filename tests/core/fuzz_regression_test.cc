// What the fuzzers of tests/fuzz and the sanitizer build found (README "Reliability:
// fuzzing and sanitizers"), one test per finding with the input that broke the parser, plus
// the in-memory entry points the fuzzers use (they must read exactly what the file readers
// read).
#include <map>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/cameramodel_io.h"
#include "pipeline/core/poses.h"
#include "pipeline/core/project.h"
#include "pipeline/core/scene.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

using ::testing::HasSubstr;

std::string Nested(const std::string& open, const std::string& close, int depth) {
  std::string text;
  for (int i = 0; i < depth; ++i) text += open;
  for (int i = 0; i < depth; ++i) text += close;
  return text;
}

// A minimal glTF (no geometry) whose asset.extras is `extras`.
std::string GltfWithExtras(const std::string& extras) {
  std::string text = R"({"asset": {"version": "2.0", "extras": )";
  text += extras;
  text += "}}";
  return text;
}

// The same JSON as a GLB (JSON chunk only).
std::string Glb(std::string json) {
  while (json.size() % 4 != 0) json += ' ';
  auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  std::string glb = "glTF";
  glb += u32(2);
  glb += u32(static_cast<uint32_t>(12 + 8 + json.size()));
  glb += u32(static_cast<uint32_t>(json.size()));
  glb += "JSON";
  glb += json;
  return glb;
}

// gltf_fuzz (hand-made input): tinygltf reads `extras` recursively; 30,000 nested arrays
// overflowed the stack (a crash). Now: a clear error, no crash.
TEST(FuzzRegressionTest, DeeplyNestedGltfJsonIsAnError) {
  for (const bool binary : {false, true}) {
    SCOPED_TRACE(binary ? "GLB" : "glTF");
    const std::string json = GltfWithExtras(Nested("[", "]", 200000));
    Scene scene;
    const Status status =
        ParseGltfScene(binary ? Glb(json) : json, "deep.gltf", "", SceneLoadOptions(), &scene);
    ASSERT_FALSE(status.ok());
    EXPECT_THAT(status.message(), HasSubstr("deep.gltf: cannot parse "));
    EXPECT_THAT(status.message(), HasSubstr("JSON nested more than 128 levels deep"));
  }
  // Brackets inside strings do not count, and ordinary nesting still loads (as an empty scene
  // without triangles, which is its own error).
  std::string quoted = "\"";  // a string holding brackets (and an escaped quote)
  quoted += Nested("[", "]", 1000);
  quoted += "\\\"[\"";
  const std::string strings = GltfWithExtras(quoted);
  const std::string shallow = GltfWithExtras(Nested("[", "]", 100));
  for (const std::string& json : {strings, shallow}) {
    Scene scene;
    const Status status = ParseGltfScene(json, "ok.gltf", "", SceneLoadOptions(), &scene);
    EXPECT_THAT(status.message(), ::testing::Not(HasSubstr("nested")));
  }
}

// gltf_fuzz (hand-made input): an accessor without a bufferView is all zeros, so a 200-byte
// file declaring 89 million of them made the loader allocate over 2 GB (libFuzzer:
// out-of-memory, minutes under ASan). Now: a clear error naming the accessor.
TEST(FuzzRegressionTest, HugeAccessorWithoutBufferViewIsAnError) {
  const std::string gltf = R"({"asset": {"version": "2.0"},
    "accessors": [{"componentType": 5126, "count": 89478485, "type": "VEC3"}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]})";
  Scene scene;
  const Status status = ParseGltfScene(gltf, "huge.gltf", "", SceneLoadOptions(), &scene);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("huge.gltf: "));
  EXPECT_THAT(status.message(),
              HasSubstr("accessor 0: count 89478485 without a bufferView is too large (at most "
                        "5592405)"));
}

// gltf_fuzz (the 10 s run of .ci/sanitize): a GLB whose TEXCOORD_0 holds non-finite floats
// was accepted, the fuzzer's consistency check (finite UVs) aborted. Now: an error naming the
// file, the primitive and the attribute.
TEST(FuzzRegressionTest, NonFiniteUvIsAnError) {
  std::string bytes;
  ASSERT_TRUE(ReadFileToString(
                  testing::SourceDir() + "/tests/fuzz/seeds/gltf/found-nonfinite-uv.glb", &bytes)
                  .ok());
  Scene scene;
  const Status status = ParseGltfScene(bytes, "found.glb", "", SceneLoadOptions(), &scene);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("found.glb: mesh "));
  EXPECT_THAT(status.message(), ::testing::MatchesRegex(".*: TEXCOORD_0 [0-9]+ is not finite"));
}

// project_fuzz (the 10 s run of .ci/sanitize): a number too large for a double (1e999)
// made nlohmann throw out_of_range ("number overflow"), not parse_error, so it escaped the
// project reader and aborted. Now: the one-line malformed-JSON error naming the file.
TEST(FuzzRegressionTest, NumberOverflowInProjectIsAnError) {
  for (const std::string& text :
       {std::string("88888888888e888888888\x9d"), std::string("{\"fresco\": 1e999}"),
        std::string("{\"fresco\": 1, \"pipeline\": {\"update_every\": -1e400}}")}) {
    SCOPED_TRACE(text);
    Project project;
    const Status status = ParseProject(text, "p.json", {}, &project);
    ASSERT_FALSE(status.ok());
    EXPECT_THAT(status.message(), ::testing::StartsWith("p.json: malformed JSON: "));
    EXPECT_THAT(status.message(), HasSubstr("number overflow"));
    EXPECT_EQ(status.message().find('\n'), std::string::npos);
  }
}

// A GLB image in a bufferView that runs past its buffer (the JSON declares a shorter buffer
// than the view needs): tinygltf handed stb_image the view unchecked and it read past the end
// of the buffer (ASan). Now an error naming the image and the view; with the buffer's true
// length the same file loads, its 2x2 texture decoded from the view.
TEST(FuzzRegressionTest, ImageViewPastItsBufferIsAnError) {
  std::string bytes;
  ASSERT_TRUE(
      ReadFileToString(
          testing::SourceDir() + "/tests/fuzz/seeds/gltf/found-image-view-past-buffer.glb", &bytes)
          .ok());
  Scene scene;
  const Status status = ParseGltfScene(bytes, "found.glb", "", SceneLoadOptions(), &scene);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(),
            "found.glb: images[0]: bufferViews[3] (bytes 68 + 75) runs past the end of "
            "buffers[0] (100 bytes)");

  const std::string declared = "\"byteLength\":100}", whole = "\"byteLength\":144}";
  const size_t at = bytes.find(declared);
  ASSERT_NE(at, std::string::npos);
  bytes.replace(at, declared.size(), whole);
  const Status fixed = ParseGltfScene(bytes, "fixed.glb", "", SceneLoadOptions(), &scene);
  ASSERT_TRUE(fixed.ok()) << fixed.message();
  ASSERT_EQ(scene.textures.size(), 1u);
  EXPECT_EQ(scene.textures[0].rgba.size(), cv::Size(2, 2));
  EXPECT_EQ(scene.textures[0].rgba.at<cv::Vec4b>(0, 1), cv::Vec4b(0, 255, 0, 255));
}

// A .cameramodel whose last line is a comment with no newline: libmrcal's reader ran past
// the end of the text looking for the newline (ASan). It reads like the same file without
// the comment.
TEST(FuzzRegressionTest, CommentAtTheEndOfACameraModelIsRead) {
  std::string text;
  ASSERT_TRUE(ReadFileToString(testing::SourceDir() +
                                   "/tests/fuzz/seeds/cameramodel/found-comment-at-end.cameramodel",
                               &text)
                  .ok());
  ASSERT_NE(text.back(), '\n');
  CameraModelFile with_comment, without;
  const Status status = ParseCameraModel(text, "found.cameramodel", &with_comment);
  ASSERT_TRUE(status.ok()) << status.message();
  const std::string plain = text.substr(0, text.rfind('#'));
  ASSERT_TRUE(ParseCameraModel(plain, "plain.cameramodel", &without).ok());
  EXPECT_EQ(with_comment.camera.Params(), without.camera.Params());
  EXPECT_EQ(with_comment.camera.width, 1280);
}

// The in-memory readers give what the file readers give.
TEST(FuzzRegressionTest, InMemoryReadersMatchFileReaders) {
  const std::string source = testing::SourceDir();
  const std::string gltf_path = source + "/projects/static-cam/plane.gltf";
  Scene from_file, from_memory;
  ASSERT_TRUE(LoadGltfScene(gltf_path, SceneLoadOptions(), &from_file).ok());
  std::string bytes;
  ASSERT_TRUE(ReadFileToString(gltf_path, &bytes).ok());
  const Status status = ParseGltfScene(bytes, gltf_path, source + "/projects/static-cam",
                                       SceneLoadOptions(), &from_memory);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(from_memory.mesh.NumTriangles(), from_file.mesh.NumTriangles());
  ASSERT_GT(from_file.mesh.NumTriangles(), 0);
  EXPECT_EQ(from_memory.mesh.vertices, from_file.mesh.vertices);
  EXPECT_EQ(from_memory.mesh.triangles, from_file.mesh.triangles);
  EXPECT_EQ(from_memory.source_path, gltf_path);

  const std::string tum_path = source + "/projects/static-cam/car-detection.tum";
  std::vector<PosedImage> tum_file, tum_memory;
  ASSERT_TRUE(ReadTumTrajectory(tum_path, &tum_file).ok());
  ASSERT_TRUE(ReadFileToString(tum_path, &bytes).ok());
  ASSERT_TRUE(ParseTumTrajectory(bytes, tum_path, &tum_memory).ok());
  ASSERT_EQ(tum_memory.size(), tum_file.size());
  ASSERT_GT(tum_file.size(), 100u);
  for (size_t i = 0; i < tum_file.size(); ++i) {
    EXPECT_EQ(tum_memory[i].timestamp_s, tum_file[i].timestamp_s);
    EXPECT_EQ(tum_memory[i].cam_from_world.translation, tum_file[i].cam_from_world.translation);
  }

  const std::string cameras_path = source + "/projects/static-cam/cameras.txt";
  std::map<int, Camera> cameras_file, cameras_memory;
  ASSERT_TRUE(ReadColmapCameras(cameras_path, &cameras_file).ok());
  ASSERT_TRUE(ReadFileToString(cameras_path, &bytes).ok());
  ASSERT_TRUE(ParseColmapCameras(bytes, cameras_path, &cameras_memory).ok());
  ASSERT_EQ(cameras_memory.size(), 1u);
  EXPECT_EQ(cameras_memory.begin()->second.Params(), cameras_file.begin()->second.Params());
  // Errors name the file given.
  std::vector<PosedImage> images;
  EXPECT_THAT(ParseColmapImages("1 2 3\n", "sparse/images.txt", &images).message(),
              HasSubstr("sparse/images.txt:1: "));
}

}  // namespace
}  // namespace fresco
