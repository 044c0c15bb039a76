// glTF scenes: save/load round trips, node transforms, map-scale precision, winding under
// mirroring, accessor variants (index types, strides, normalized UVs, sparse, strips, fans),
// bad input, and the real sample models in ../shared/data/gltf.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/scene.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using ::fresco::testing::MakeTempDir;
using ::fresco::testing::ReadText;
using ::fresco::testing::SharedDataDir;
using ::fresco::testing::WriteText;
using nlohmann::json;
using ::testing::HasSubstr;

// ----------------------------------------------------------------------------------------
// Fixtures built in memory

// A 4x4 RGBA checker with distinct texels and varied alpha (incl. 0 with non-zero colour).
cv::Mat CheckerRgba() {
  cv::Mat rgba(4, 4, CV_8UC4);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) {
      const bool dark = (x + y) % 2 == 1;
      rgba.at<cv::Vec4b>(y, x) = cv::Vec4b(dark ? 10 + x : 240 - y, 16 * x + y, 16 * y + x + 3,
                                           static_cast<uint8_t>(x == 3 && y == 0 ? 0 : 85 * x));
    }
  }
  return rgba;
}

// Unit cube, 24 vertices (split per face), 12 outward CCW triangles with UVs; faces 0-2 use
// material 0 (textured), faces 3-5 material 1 (no texture, no UVs).
Scene CubeScene(const Eigen::Vector3d& origin) {
  Scene scene;
  TriangleMesh& mesh = scene.mesh;
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                        z = Eigen::Vector3d::UnitZ();
  const std::array<std::array<Eigen::Vector3d, 3>, 6> faces = {
      {{x, y, z}, {-x, z, y}, {y, z, x}, {-y, x, z}, {z, x, y}, {-z, y, x}}};
  const std::array<Eigen::Vector2f, 4> corner_uv = {Eigen::Vector2f(0, 1), Eigen::Vector2f(1, 1),
                                                    Eigen::Vector2f(1, 0), Eigen::Vector2f(0, 0)};
  for (int f = 0; f < 6; ++f) {
    const auto& [n, u, v] = faces[f];
    const int base = static_cast<int>(mesh.vertices.size());
    mesh.vertices.push_back(0.5 * (n - u - v));
    mesh.vertices.push_back(0.5 * (n + u - v));
    mesh.vertices.push_back(0.5 * (n + u + v));
    mesh.vertices.push_back(0.5 * (n - u + v));
    const bool textured = f < 3;
    const float s = 0.25f * f;  // different UVs per face
    auto uv = [&](int c) {
      return textured ? Eigen::Vector2f(corner_uv[c] * 0.5f + Eigen::Vector2f(s, 0.125f))
                      : Eigen::Vector2f::Zero();
    };
    mesh.triangles.emplace_back(base, base + 1, base + 2);
    mesh.uvs.push_back({uv(0), uv(1), uv(2)});
    mesh.triangles.emplace_back(base, base + 2, base + 3);
    mesh.uvs.push_back({uv(0), uv(2), uv(3)});
    for (int k = 0; k < 2; ++k) {
      mesh.material.push_back(textured ? 0 : 1);
      mesh.has_uv.push_back(textured);
    }
  }
  Material textured;
  textured.name = "checker";
  textured.base_color_texture = 0;
  textured.base_color_factor = {1.0, 0.5, 0.25, 0.875};
  Material plain;
  plain.name = "plain";
  plain.base_color_factor = {0.1, 0.2, 0.3, 1.0};
  plain.double_sided = true;
  scene.materials = {textured, plain};
  Texture texture;
  texture.rgba = CheckerRgba();
  texture.name = "checker_tex";
  texture.wrap_s = TextureWrap::kClampToEdge;
  texture.wrap_t = TextureWrap::kMirroredRepeat;
  scene.textures = {texture};
  scene.origin_in_world = origin;
  return scene;
}

void ExpectSameTexels(const cv::Mat& a, const cv::Mat& b) {
  ASSERT_EQ(a.type(), CV_8UC4);
  ASSERT_EQ(b.type(), CV_8UC4);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
}

void ExpectScenesEqual(const Scene& expected, const Scene& actual) {
  EXPECT_EQ(actual.origin_in_world, expected.origin_in_world);
  ASSERT_EQ(actual.mesh.vertices.size(), expected.mesh.vertices.size());
  for (size_t v = 0; v < expected.mesh.vertices.size(); ++v) {
    EXPECT_EQ(actual.mesh.vertices[v], expected.mesh.vertices[v]) << "vertex " << v;
  }
  ASSERT_EQ(actual.mesh.NumTriangles(), expected.mesh.NumTriangles());
  for (int t = 0; t < expected.mesh.NumTriangles(); ++t) {
    EXPECT_EQ(actual.mesh.triangles[t], expected.mesh.triangles[t]) << "triangle " << t;
    EXPECT_EQ(actual.mesh.material[t], expected.mesh.material[t]) << "triangle " << t;
    EXPECT_EQ(actual.mesh.has_uv[t], expected.mesh.has_uv[t]) << "triangle " << t;
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(actual.mesh.uvs[t][k], expected.mesh.uvs[t][k]) << "triangle " << t;
    }
  }
  ASSERT_EQ(actual.materials.size(), expected.materials.size());
  for (size_t m = 0; m < expected.materials.size(); ++m) {
    EXPECT_EQ(actual.materials[m].name, expected.materials[m].name);
    EXPECT_EQ(actual.materials[m].base_color_factor, expected.materials[m].base_color_factor);
    EXPECT_EQ(actual.materials[m].base_color_texture, expected.materials[m].base_color_texture);
    EXPECT_EQ(actual.materials[m].double_sided, expected.materials[m].double_sided);
  }
  ASSERT_EQ(actual.textures.size(), expected.textures.size());
  for (size_t t = 0; t < expected.textures.size(); ++t) {
    EXPECT_EQ(actual.textures[t].name, expected.textures[t].name);
    EXPECT_EQ(actual.textures[t].wrap_s, expected.textures[t].wrap_s);
    EXPECT_EQ(actual.textures[t].wrap_t, expected.textures[t].wrap_t);
    ExpectSameTexels(actual.textures[t].rgba, expected.textures[t].rgba);
  }
}

// ----------------------------------------------------------------------------------------
// Hand-written glTF documents with an embedded (base64) buffer

std::string Base64(const std::string& bytes) {
  static const char* kTable = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v =
        (uint8_t(bytes[i]) << 16) | (uint8_t(bytes[i + 1]) << 8) | uint8_t(bytes[i + 2]);
    for (int s = 18; s >= 0; s -= 6) out += kTable[(v >> s) & 63];
  }
  if (i + 1 == bytes.size()) {
    const uint32_t v = uint8_t(bytes[i]) << 16;
    out += std::string{kTable[(v >> 18) & 63], kTable[(v >> 12) & 63], '=', '='};
  } else if (i + 2 == bytes.size()) {
    const uint32_t v = (uint8_t(bytes[i]) << 16) | (uint8_t(bytes[i + 1]) << 8);
    out += std::string{kTable[(v >> 18) & 63], kTable[(v >> 12) & 63], kTable[(v >> 6) & 63], '='};
  }
  return out;
}

constexpr int kU8 = 5121, kU16 = 5123, kU32 = 5125, kFloat = 5126;

class GltfDoc {
 public:
  GltfDoc() {
    doc_["asset"] = {{"version", "2.0"}};
    doc_["accessors"] = json::array();
    doc_["bufferViews"] = json::array();
    doc_["meshes"] = json::array();
    doc_["nodes"] = json::array();
  }
  template <typename T>
  int View(const std::vector<T>& values, int stride = 0) {
    while (bin_.size() % 4) bin_.push_back('\0');
    json view = {
        {"buffer", 0}, {"byteOffset", bin_.size()}, {"byteLength", values.size() * sizeof(T)}};
    if (stride) view["byteStride"] = stride;
    bin_.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
    doc_["bufferViews"].push_back(view);
    return static_cast<int>(doc_["bufferViews"].size()) - 1;
  }
  int Accessor(int view, int component_type, size_t count, const std::string& type,
               size_t byte_offset = 0, bool normalized = false) {
    json acc = {{"componentType", component_type}, {"count", count}, {"type", type}};
    if (view >= 0) acc["bufferView"] = view;
    if (byte_offset) acc["byteOffset"] = byte_offset;
    if (normalized) acc["normalized"] = true;
    doc_["accessors"].push_back(acc);
    return static_cast<int>(doc_["accessors"].size()) - 1;
  }
  int Positions(const std::vector<float>& xyz) {
    return Accessor(View(xyz), kFloat, xyz.size() / 3, "VEC3");
  }
  int Indices16(const std::vector<uint16_t>& indices) {
    return Accessor(View(indices), kU16, indices.size(), "SCALAR");
  }
  // A mesh with one primitive; returns the mesh index.
  int Mesh(const std::string& name, json primitive) {
    doc_["meshes"].push_back({{"name", name}, {"primitives", json::array({primitive})}});
    return static_cast<int>(doc_["meshes"].size()) - 1;
  }
  int Node(json node) {
    doc_["nodes"].push_back(node);
    return static_cast<int>(doc_["nodes"].size()) - 1;
  }
  void Scene(const std::vector<int>& roots) {
    doc_["scenes"] = json::array({{{"nodes", roots}}});
    doc_["scene"] = 0;
  }
  json& doc() { return doc_; }
  std::string Write(const std::string& dir, const std::string& name) {
    doc_["buffers"] =
        json::array({{{"byteLength", bin_.size()},
                      {"uri", "data:application/octet-stream;base64," + Base64(bin_)}}});
    const std::string path = dir + "/" + name;
    WriteText(path, doc_.dump(1));
    return path;
  }

 private:
  json doc_;
  std::string bin_;
};

// One triangle (0,0,0), (1,0,0), (0,1,0) in mesh "Tri" (CCW seen from +z).
const std::vector<float> kTriangle = {0, 0, 0, 1, 0, 0, 0, 1, 0};

Scene LoadOk(const std::string& path, bool recentre = false) {
  SceneLoadOptions options;
  options.recentre = recentre;
  Scene scene;
  const Status status = LoadGltfScene(path, options, &scene);
  EXPECT_TRUE(status.ok()) << status.message();
  return scene;
}

std::string LoadError(const std::string& path) {
  Scene scene;
  const Status status = LoadGltfScene(path, SceneLoadOptions(), &scene);
  EXPECT_FALSE(status.ok());
  return status.message();
}

// ----------------------------------------------------------------------------------------
// Round trips

TEST(GltfSceneTest, SaveLoadRoundTripIsExact) {
  const std::string dir = MakeTempDir("scene");
  const Scene original = CubeScene(Eigen::Vector3d(10.0, -5.0, 2.5));
  const std::string path = dir + "/out/cube.gltf";
  const Status saved = SaveGltfScene(original, path);
  ASSERT_TRUE(saved.ok()) << saved.message();
  EXPECT_TRUE(fs::exists(dir + "/out/cube.bin"));
  EXPECT_TRUE(fs::exists(dir + "/out/cube_texture0.png"));
  // No temp files left behind.
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir + "/out")) files += entry.is_regular_file();
  EXPECT_EQ(files, 3);

  Scene loaded;
  const Status status = LoadGltfScene(path, SceneLoadOptions(), &loaded);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(loaded.source_path, path);
  EXPECT_EQ(loaded.dropped_degenerate, 0);
  ExpectScenesEqual(original, loaded);
  // The PNG itself holds the RGBA texels (alpha 0 texel keeps its colour).
  cv::Mat png = cv::imread(dir + "/out/cube_texture0.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(png.type(), CV_8UC4);
  cv::cvtColor(png, png, cv::COLOR_BGRA2RGBA);
  ExpectSameTexels(png, original.textures[0].rgba);
  EXPECT_EQ(loaded.textures[0].rgba.at<cv::Vec4b>(0, 3), cv::Vec4b(13, 48, 6, 0));

  // Saving the loaded scene again gives the same scene once more.
  ASSERT_TRUE(SaveGltfScene(loaded, dir + "/again.gltf").ok());
  ExpectScenesEqual(original, LoadOk(dir + "/again.gltf", true));
}

TEST(GltfSceneTest, RoundTripWithoutRecentreKeepsWorldPositions) {
  const std::string dir = MakeTempDir("scene");
  const Scene original = CubeScene(Eigen::Vector3d(10.0, -5.0, 2.5));
  ASSERT_TRUE(SaveGltfScene(original, dir + "/cube.gltf").ok());
  const Scene loaded = LoadOk(dir + "/cube.gltf", /*recentre=*/false);
  EXPECT_EQ(loaded.origin_in_world, Eigen::Vector3d::Zero());
  ASSERT_EQ(loaded.mesh.vertices.size(), original.mesh.vertices.size());
  for (size_t v = 0; v < original.mesh.vertices.size(); ++v) {
    EXPECT_EQ(loaded.WorldFromLocal(loaded.mesh.vertices[v]),
              original.WorldFromLocal(original.mesh.vertices[v]));
  }
}

TEST(GltfSceneTest, SaveSplitsVerticesWithSeveralUvs) {
  // A quad whose two triangles use different UVs on the shared diagonal vertices.
  Scene scene;
  scene.mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  scene.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  scene.mesh.uvs = {
      {Eigen::Vector2f(0, 0), Eigen::Vector2f(1, 0), Eigen::Vector2f(1, 1)},
      {Eigen::Vector2f(0.5f, 0.5f), Eigen::Vector2f(0.25f, 1), Eigen::Vector2f(0, 1)}};
  scene.mesh.material = {0, 0};
  scene.mesh.has_uv = {true, true};
  scene.materials.resize(1);
  const std::string dir = MakeTempDir("scene");
  ASSERT_TRUE(SaveGltfScene(scene, dir + "/quad.gltf").ok());
  const Scene loaded = LoadOk(dir + "/quad.gltf");
  ASSERT_EQ(loaded.mesh.NumTriangles(), 2);
  EXPECT_EQ(loaded.mesh.vertices.size(), 6u);  // 4 + 2 split copies
  for (int t = 0; t < 2; ++t) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(loaded.mesh.Corner(t, k), scene.mesh.Corner(t, k));
      EXPECT_EQ(loaded.mesh.uvs[t][k], scene.mesh.uvs[t][k]);
    }
  }
}

// Triangles of two materials interleaved in the mesh's order (charts on two atlas pages):
// one primitive per material, not one per run, and every triangle kept with its material.
TEST(GltfSceneTest, SaveMakesOnePrimitivePerMaterialHoweverTrianglesInterleave) {
  Scene scene;
  const int n = 40;
  for (int i = 0; i <= n; ++i) {
    scene.mesh.vertices.emplace_back(i, 0, 0);
    scene.mesh.vertices.emplace_back(i, 1, 0);
  }
  for (int i = 0; i < n; ++i) {
    scene.mesh.triangles.push_back({2 * i, 2 * i + 2, 2 * i + 1});
    scene.mesh.material.push_back(i % 2);
  }
  scene.mesh.uvs.assign(n, {Eigen::Vector2f::Zero(), Eigen::Vector2f::Zero(),
                            Eigen::Vector2f::Zero()});
  scene.mesh.has_uv.assign(n, false);
  scene.materials.resize(2);
  scene.materials[1].base_color_factor = Eigen::Vector4d(1, 0, 0, 1);
  const std::string dir = MakeTempDir("scene");
  ASSERT_TRUE(SaveGltfScene(scene, dir + "/strip.gltf").ok());
  const json doc = json::parse(ReadText(dir + "/strip.gltf"));
  EXPECT_EQ(doc["meshes"][0]["primitives"].size(), 2u);
  const Scene loaded = LoadOk(dir + "/strip.gltf", /*recentre=*/false);
  ASSERT_EQ(loaded.mesh.NumTriangles(), n);
  // Each material's triangles in their order: the even ones, then the odd ones.
  for (int j = 0; j < n; ++j) {
    const int t = j < n / 2 ? 2 * j : 2 * (j - n / 2) + 1;
    for (int k = 0; k < 3; ++k) EXPECT_EQ(loaded.mesh.Corner(j, k), scene.mesh.Corner(t, k)) << j;
    EXPECT_EQ(loaded.materials[loaded.mesh.material[j]].base_color_factor,
              scene.materials[t % 2].base_color_factor)
        << j;
  }
}

TEST(GltfSceneTest, SaveRejectsInvalidScenes) {
  const std::string dir = MakeTempDir("scene");
  Scene empty;
  EXPECT_THAT(SaveGltfScene(empty, dir + "/empty.gltf").message(), HasSubstr("no triangles"));
  Scene bad_texture = CubeScene(Eigen::Vector3d::Zero());
  bad_texture.materials[1].base_color_texture = 3;
  EXPECT_THAT(SaveGltfScene(bad_texture, dir + "/bad.gltf").message(),
              HasSubstr("bad.gltf: material 1: texture 3 out of range"));
  Scene bad_index = CubeScene(Eigen::Vector3d::Zero());
  bad_index.mesh.triangles[5][1] = 99;
  EXPECT_THAT(SaveGltfScene(bad_index, dir + "/bad.gltf").message(),
              HasSubstr("triangle 5: vertex 99 out of range (24 vertices)"));
  EXPECT_FALSE(fs::exists(dir + "/bad.gltf"));
}

// ----------------------------------------------------------------------------------------
// Node hierarchy and precision

TEST(GltfSceneTest, NodeTransformsCompose) {
  GltfDoc doc;
  const int mesh = doc.Mesh("Tri", {{"attributes", {{"POSITION", doc.Positions(kTriangle)}}}});
  // child: rotate 90 deg about z, then translate (0, 2, 0); parent: translate (10, 0, 0).
  const double h = std::sqrt(0.5);
  const int child =
      doc.Node({{"mesh", mesh}, {"rotation", {0, 0, h, h}}, {"translation", {0, 2, 0}}});
  const int parent = doc.Node({{"translation", {10, 0, 0}}, {"children", {child}}});
  // A second instance through a column-major matrix: scale 2, translate (0, 0, 5).
  const int matrix_node =
      doc.Node({{"mesh", mesh}, {"matrix", {2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 0, 0, 5, 1}}});
  doc.Scene({parent, matrix_node});
  const Scene scene = LoadOk(doc.Write(MakeTempDir("scene"), "nodes.gltf"));
  ASSERT_EQ(scene.mesh.NumTriangles(), 2);
  const std::vector<Eigen::Vector3d> expected = {{10, 2, 0}, {10, 3, 0}, {9, 2, 0},
                                                 {0, 0, 5},  {2, 0, 5},  {0, 2, 5}};
  for (int t = 0; t < 2; ++t) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_LT((scene.mesh.Corner(t, k) - expected[3 * t + k]).norm(), 1e-12)
          << "triangle " << t << " corner " << k << ": " << scene.mesh.Corner(t, k).transpose();
    }
  }
  EXPECT_EQ(scene.materials.size(), 1u);  // default white
  EXPECT_EQ(scene.materials[0].base_color_factor, Eigen::Vector4d::Ones());
  EXPECT_EQ(scene.mesh.material, (std::vector<int>{0, 0}));
  EXPECT_EQ(scene.mesh.has_uv, (std::vector<bool>{false, false}));
}

TEST(GltfSceneTest, NoSceneUsesAllRootNodes) {
  GltfDoc doc;
  const int mesh = doc.Mesh("Tri", {{"attributes", {{"POSITION", doc.Positions(kTriangle)}}}});
  const int child = doc.Node({{"mesh", mesh}, {"translation", {0, 0, 1}}});
  doc.Node({{"mesh", mesh}, {"children", {child}}});
  doc.Node({{"mesh", mesh}, {"translation", {0, 0, -1}}});
  const Scene scene = LoadOk(doc.Write(MakeTempDir("scene"), "noscene.gltf"));
  EXPECT_EQ(scene.mesh.NumTriangles(), 3);  // root 1 + its child + root 2, child not twice
}

TEST(GltfSceneTest, MapScaleSceneKeepsLocalPrecision) {
  // Irregular float coordinates (not exactly representable sums) near a map origin.
  const std::vector<float> xyz = {0.1234567f, 0.7654321f, 0.0111f,    1.3333333f, 0.25f,
                                  0.0123f,    0.2222222f, 1.9876543f, 0.3f};
  auto write = [&](const Eigen::Vector3d& translation, const std::string& name) {
    GltfDoc doc;
    const int mesh = doc.Mesh("Tri", {{"attributes", {{"POSITION", doc.Positions(xyz)}}}});
    doc.Scene({doc.Node(
        {{"mesh", mesh}, {"translation", {translation.x(), translation.y(), translation.z()}}})});
    return doc.Write(MakeTempDir("scene"), name);
  };
  const Scene near = LoadOk(write(Eigen::Vector3d::Zero(), "near.gltf"), true);
  const Scene far = LoadOk(write(Eigen::Vector3d(1e6, 2e6, 0), "far.gltf"), true);
  EXPECT_LT((far.origin_in_world - near.origin_in_world - Eigen::Vector3d(1e6, 2e6, 0)).norm(),
            1e-9);
  ASSERT_EQ(far.mesh.vertices.size(), 3u);
  for (int v = 0; v < 3; ++v) {
    EXPECT_LT((far.mesh.vertices[v] - near.mesh.vertices[v]).norm(), 1e-6) << "vertex " << v;
  }
  EXPECT_NEAR(far.mesh.Area(0), near.mesh.Area(0), 1e-9);

  // Saving the far scene (float positions relative to the origin) and loading it back
  // keeps world positions to well under a millimetre.
  const std::string dir = MakeTempDir("scene");
  ASSERT_TRUE(SaveGltfScene(far, dir + "/far_saved.gltf").ok());
  const Scene reloaded = LoadOk(dir + "/far_saved.gltf", true);
  for (int v = 0; v < 3; ++v) {
    EXPECT_LT((reloaded.WorldFromLocal(reloaded.mesh.vertices[v]) -
               far.WorldFromLocal(far.mesh.vertices[v]))
                  .norm(),
              1e-6);
  }
}

TEST(GltfSceneTest, NegativeScaleKeepsCounterClockwiseFront) {
  GltfDoc doc;
  const std::vector<float> uv = {0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 1.0f};
  const int uv_accessor = doc.Accessor(doc.View(uv), kFloat, 3, "VEC2");
  const int mesh = doc.Mesh(
      "Tri",
      {{"attributes", {{"POSITION", doc.Positions(kTriangle)}, {"TEXCOORD_0", uv_accessor}}}});
  const int plain = doc.Node({{"mesh", mesh}});
  const int mirrored = doc.Node({{"mesh", mesh}, {"scale", {-1, 1, 1}}});
  doc.Scene({plain, mirrored});
  const Scene scene = LoadOk(doc.Write(MakeTempDir("scene"), "mirror.gltf"));
  ASSERT_EQ(scene.mesh.NumTriangles(), 2);
  // The mirrored triangle (0,0,0), (-1,0,0), (0,1,0) would face -z; winding is fixed so its
  // front is +z like the original.
  EXPECT_TRUE(scene.mesh.Normal(0).isApprox(Eigen::Vector3d(0, 0, 1)));
  EXPECT_TRUE(scene.mesh.Normal(1).isApprox(Eigen::Vector3d(0, 0, 1)))
      << scene.mesh.Normal(1).transpose();
  // UVs follow their corners.
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d p = scene.mesh.Corner(1, k);
    const Eigen::Vector2f expected = p.x() < -0.5  ? Eigen::Vector2f(1, 0)
                                     : p.y() > 0.5 ? Eigen::Vector2f(0, 1)
                                                   : Eigen::Vector2f(0, 0);
    EXPECT_EQ(scene.mesh.uvs[1][k], expected) << "corner " << k;
  }
}

// ----------------------------------------------------------------------------------------
// Accessor and primitive variants

TEST(GltfSceneTest, IndexTypesGiveTheSameTriangles) {
  const std::vector<float> quad = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  GltfDoc doc;
  const int positions = doc.Positions(quad);
  const std::vector<uint8_t> i8 = {0, 1, 2, 0, 2, 3};
  const std::vector<uint16_t> i16 = {0, 1, 2, 0, 2, 3};
  const std::vector<uint32_t> i32 = {0, 1, 2, 0, 2, 3};
  const int a8 = doc.Accessor(doc.View(i8), kU8, 6, "SCALAR");
  const int a16 = doc.Accessor(doc.View(i16), kU16, 6, "SCALAR");
  const int a32 = doc.Accessor(doc.View(i32), kU32, 6, "SCALAR");
  std::vector<int> nodes;
  for (int indices : {a8, a16, a32}) {
    const int mesh =
        doc.Mesh("Quad", {{"attributes", {{"POSITION", positions}}}, {"indices", indices}});
    nodes.push_back(doc.Node({{"mesh", mesh}}));
  }
  // Non-indexed: 6 vertices.
  const std::vector<float> soup = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0};
  nodes.push_back(doc.Node(
      {{"mesh", doc.Mesh("Soup", {{"attributes", {{"POSITION", doc.Positions(soup)}}}})}}));
  doc.Scene(nodes);
  const Scene scene = LoadOk(doc.Write(MakeTempDir("scene"), "indices.gltf"));
  ASSERT_EQ(scene.mesh.NumTriangles(), 8);
  for (int m = 0; m < 4; ++m) {
    for (int t = 0; t < 2; ++t) {
      for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(scene.mesh.Corner(2 * m + t, k), scene.mesh.Corner(t, k)) << "mesh " << m;
      }
    }
  }
  EXPECT_EQ(scene.mesh.Corner(1, 2), Eigen::Vector3d(0, 1, 0));
}

TEST(GltfSceneTest, InterleavedStrideAndNormalizedUvs) {
  // Interleaved: x y z (float) + u v (u16 normalized) + 2 bytes padding = 16-byte stride.
  struct Vertex {
    float xyz[3];
    uint16_t uv[2];
  };
  static_assert(sizeof(Vertex) == 16);
  const std::vector<Vertex> vertices = {
      {{0, 0, 0}, {0, 65535}}, {{2, 0, 0}, {65535, 65535}}, {{0, 2, 0}, {0, 32768}}};
  GltfDoc doc;
  const int view = doc.View(vertices, sizeof(Vertex));
  const int positions = doc.Accessor(view, kFloat, 3, "VEC3");
  const int uvs = doc.Accessor(view, kU16, 3, "VEC2", 12, /*normalized=*/true);
  const int mesh =
      doc.Mesh("Tri", {{"attributes", {{"POSITION", positions}, {"TEXCOORD_0", uvs}}}});
  doc.Scene({doc.Node({{"mesh", mesh}})});
  const Scene scene = LoadOk(doc.Write(MakeTempDir("scene"), "stride.gltf"));
  ASSERT_EQ(scene.mesh.NumTriangles(), 1);
  EXPECT_EQ(scene.mesh.Corner(0, 1), Eigen::Vector3d(2, 0, 0));
  EXPECT_EQ(scene.mesh.Corner(0, 2), Eigen::Vector3d(0, 2, 0));
  EXPECT_TRUE(scene.mesh.has_uv[0]);
  EXPECT_EQ(scene.mesh.uvs[0][0], Eigen::Vector2f(0, 1));
  EXPECT_EQ(scene.mesh.uvs[0][1], Eigen::Vector2f(1, 1));
  EXPECT_FLOAT_EQ(scene.mesh.uvs[0][2].y(), 32768.0f / 65535.0f);
}

TEST(GltfSceneTest, SparseAccessorOverridesValues) {
  GltfDoc doc;
  // Base positions: a triangle with vertex 2 at (0, 1, 0); sparse moves vertex 2 to (0, 4, 0).
  const int view = doc.View(kTriangle);
  const std::vector<uint16_t> sparse_indices = {2};
  const std::vector<float> sparse_values = {0, 4, 0};
  const int indices_view = doc.View(sparse_indices);
  const int values_view = doc.View(sparse_values);
  const int positions = doc.Accessor(view, kFloat, 3, "VEC3");
  doc.doc()["accessors"][positions]["sparse"] = {
      {"count", 1},
      {"indices", {{"bufferView", indices_view}, {"componentType", kU16}}},
      {"values", {{"bufferView", values_view}}}};
  const int mesh = doc.Mesh("Tri", {{"attributes", {{"POSITION", positions}}}});
  doc.Scene({doc.Node({{"mesh", mesh}})});
  const Scene scene = LoadOk(doc.Write(MakeTempDir("scene"), "sparse.gltf"));
  ASSERT_EQ(scene.mesh.NumTriangles(), 1);
  EXPECT_EQ(scene.mesh.Corner(0, 2), Eigen::Vector3d(0, 4, 0));
  EXPECT_EQ(scene.mesh.Area(0), 2.0);
}

TEST(GltfSceneTest, StripsAndFansBecomeTrianglesPointsAndLinesAreSkipped) {
  // Strip 0 1 2 3 over a quad, and a fan around vertex 0 over a pentagon, all facing +z.
  const std::vector<float> strip = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  const std::vector<float> fan = {0, 0, 0, 1, 0, 0, 1.5f, 1, 0, 0.5f, 2, 0, -0.5f, 1, 0};
  GltfDoc doc;
  const int strip_mesh =
      doc.Mesh("Strip", {{"attributes", {{"POSITION", doc.Positions(strip)}}}, {"mode", 5}});
  const int fan_mesh =
      doc.Mesh("Fan", {{"attributes", {{"POSITION", doc.Positions(fan)}}}, {"mode", 6}});
  const int points_mesh =
      doc.Mesh("Points", {{"attributes", {{"POSITION", doc.Positions(strip)}}}, {"mode", 0}});
  const int lines_mesh =
      doc.Mesh("Lines", {{"attributes", {{"POSITION", doc.Positions(strip)}}}, {"mode", 1}});
  doc.Scene({doc.Node({{"mesh", strip_mesh}}), doc.Node({{"mesh", fan_mesh}}),
             doc.Node({{"mesh", points_mesh}}), doc.Node({{"mesh", lines_mesh}})});
  const Scene scene = LoadOk(doc.Write(MakeTempDir("scene"), "strips.gltf"));
  ASSERT_EQ(scene.mesh.NumTriangles(), 2 + 3);
  EXPECT_EQ(scene.skipped_primitives, 2);
  double area = 0;
  for (int t = 0; t < scene.mesh.NumTriangles(); ++t) {
    EXPECT_TRUE(scene.mesh.Normal(t).isApprox(Eigen::Vector3d(0, 0, 1))) << "triangle " << t;
    area += scene.mesh.Area(t);
  }
  EXPECT_NEAR(area, 1.0 + 2.5, 1e-6);              // quad 1 + pentagon 2.5
  EXPECT_EQ(scene.mesh.vertices.size(), 4u + 5u);  // points/lines vertices not added
}

TEST(GltfSceneTest, DegenerateTrianglesAreDroppedAndCounted) {
  // A quad plus a zero-area triangle (collinear) and a repeated-index triangle.
  const std::vector<float> xyz = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 2, 0, 0, 5, 5, 5};
  GltfDoc doc;
  const int mesh =
      doc.Mesh("Quad", {{"attributes", {{"POSITION", doc.Positions(xyz)}}},
                        {"indices", doc.Indices16({0, 1, 2, 0, 1, 4, 0, 2, 3, 2, 2, 3})}});
  doc.Scene({doc.Node({{"mesh", mesh}})});
  const Scene scene = LoadOk(doc.Write(MakeTempDir("scene"), "degenerate.gltf"));
  EXPECT_EQ(scene.mesh.NumTriangles(), 2);
  EXPECT_EQ(scene.dropped_degenerate, 2);
  // Vertices used only by dropped triangles (4) and unused ones (5) are not kept.
  EXPECT_EQ(scene.mesh.vertices.size(), 4u);
}

TEST(GltfSceneTest, TexturesMaterialsAndSamplersFromFile) {
  const std::string dir = MakeTempDir("scene");
  // A 16-bit RGB PNG (scaled to 8 bits on load) and an 8-bit grey PNG.
  cv::Mat rgb16(2, 3, CV_16UC3);
  rgb16.setTo(cv::Scalar(0, 0, 0));
  rgb16.at<cv::Vec3w>(0, 0) = cv::Vec3w(65535, 32896, 0);  // BGR in OpenCV
  rgb16.at<cv::Vec3w>(1, 2) = cv::Vec3w(257, 514, 771);
  ASSERT_TRUE(cv::imwrite(dir + "/deep.png", rgb16));
  cv::Mat grey(5, 7, CV_8UC1, cv::Scalar(77));
  ASSERT_TRUE(cv::imwrite(dir + "/grey.png", grey));

  GltfDoc doc;
  const std::vector<float> uv = {0, 0, 1, 0, 0, 1};
  const int positions = doc.Positions(kTriangle);
  const int uvs = doc.Accessor(doc.View(uv), kFloat, 3, "VEC2");
  json& d = doc.doc();
  d["images"] = {{{"uri", "deep.png"}}, {{"uri", "grey.png"}, {"name", "grey_image"}}};
  d["samplers"] = {{{"wrapS", 33071}, {"wrapT", 33648}}};
  d["textures"] = {{{"source", 0}, {"sampler", 0}, {"name", "deep"}}, {{"source", 1}}};
  d["materials"] = {
      {{"name", "m_deep"},
       {"pbrMetallicRoughness",
        {{"baseColorTexture", {{"index", 0}}}, {"baseColorFactor", {0.5, 0.25, 1, 1}}}},
       {"doubleSided", true}},
      {{"name", "m_grey"}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 1}}}}}}};
  const int mesh0 = doc.Mesh(
      "A", {{"attributes", {{"POSITION", positions}, {"TEXCOORD_0", uvs}}}, {"material", 0}});
  const int mesh1 = doc.Mesh(
      "B", {{"attributes", {{"POSITION", positions}, {"TEXCOORD_0", uvs}}}, {"material", 1}});
  const int mesh2 = doc.Mesh("C", {{"attributes", {{"POSITION", positions}}}});
  doc.Scene(
      {doc.Node({{"mesh", mesh0}}), doc.Node({{"mesh", mesh1}}), doc.Node({{"mesh", mesh2}})});
  const Scene scene = LoadOk(doc.Write(dir, "textures.gltf"));

  ASSERT_EQ(scene.materials.size(), 3u);  // 2 + default for mesh C
  EXPECT_EQ(scene.mesh.material, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(scene.materials[0].name, "m_deep");
  EXPECT_EQ(scene.materials[0].base_color_factor, Eigen::Vector4d(0.5, 0.25, 1, 1));
  EXPECT_TRUE(scene.materials[0].double_sided);
  EXPECT_EQ(scene.materials[0].base_color_texture, 0);
  EXPECT_FALSE(scene.materials[1].double_sided);
  EXPECT_EQ(scene.materials[1].base_color_texture, 1);
  EXPECT_EQ(scene.materials[2].base_color_texture, -1);
  EXPECT_EQ(scene.materials[2].base_color_factor, Eigen::Vector4d::Ones());
  EXPECT_EQ(scene.mesh.has_uv, (std::vector<bool>{true, true, false}));

  ASSERT_EQ(scene.textures.size(), 2u);
  const Texture& deep = scene.textures[0];
  EXPECT_EQ(deep.name, "deep");
  EXPECT_EQ(deep.wrap_s, TextureWrap::kClampToEdge);
  EXPECT_EQ(deep.wrap_t, TextureWrap::kMirroredRepeat);
  ASSERT_EQ(deep.rgba.type(), CV_8UC4);
  ASSERT_EQ(deep.rgba.size(), cv::Size(3, 2));
  EXPECT_EQ(deep.rgba.at<cv::Vec4b>(0, 0), cv::Vec4b(0, 128, 255, 255));  // RGBA
  EXPECT_EQ(deep.rgba.at<cv::Vec4b>(1, 2), cv::Vec4b(3, 2, 1, 255));
  EXPECT_EQ(deep.rgba.at<cv::Vec4b>(1, 0), cv::Vec4b(0, 0, 0, 255));
  const Texture& grey_texture = scene.textures[1];
  EXPECT_EQ(grey_texture.name, "grey_image");
  EXPECT_EQ(grey_texture.wrap_s, TextureWrap::kRepeat);
  ASSERT_EQ(grey_texture.rgba.size(), cv::Size(7, 5));
  EXPECT_EQ(grey_texture.rgba.at<cv::Vec4b>(4, 6), cv::Vec4b(77, 77, 77, 255));
}

// ----------------------------------------------------------------------------------------
// Bad input: errors name the file and what is wrong

TEST(GltfSceneErrorTest, MissingFile) {
  const std::string path = MakeTempDir("scene") + "/nowhere.gltf";
  EXPECT_THAT(LoadError(path), HasSubstr("nowhere.gltf: file not found"));
}

TEST(GltfSceneErrorTest, GarbageJson) {
  const std::string dir = MakeTempDir("scene");
  WriteText(dir + "/garbage.gltf", "{ this is not json ]");
  EXPECT_THAT(LoadError(dir + "/garbage.gltf"), HasSubstr("garbage.gltf: cannot parse glTF"));
  WriteText(dir + "/truncated.glb", std::string("glTF\x02\0\0\0", 8));
  EXPECT_THAT(LoadError(dir + "/truncated.glb"), HasSubstr("truncated.glb: cannot parse GLB"));
}

TEST(GltfSceneErrorTest, IndexOutOfRange) {
  GltfDoc doc;
  const int mesh = doc.Mesh("Cube", {{"attributes", {{"POSITION", doc.Positions(kTriangle)}}},
                                     {"indices", doc.Indices16({0, 1, 40})}});
  doc.Scene({doc.Node({{"mesh", mesh}})});
  const std::string path = doc.Write(MakeTempDir("scene"), "scene.gltf");
  EXPECT_THAT(LoadError(path),
              HasSubstr("scene.gltf: mesh 'Cube' primitive 0: index 40 out of range (3 vertices)"));
}

TEST(GltfSceneErrorTest, NanPosition) {
  GltfDoc doc;
  std::vector<float> xyz = kTriangle;
  xyz[4] = std::numeric_limits<float>::quiet_NaN();
  const int mesh = doc.Mesh("Tri", {{"attributes", {{"POSITION", doc.Positions(xyz)}}}});
  doc.Scene({doc.Node({{"mesh", mesh}})});
  const std::string path = doc.Write(MakeTempDir("scene"), "nan.gltf");
  EXPECT_THAT(LoadError(path),
              HasSubstr("nan.gltf: mesh 'Tri' primitive 0: POSITION 1 is not finite"));
}

// Non-finite UVs (gltf_fuzz found them accepted) and positions that overflow only once the
// node transform is applied.
TEST(GltfSceneErrorTest, NonFiniteUvAndTransformedPosition) {
  for (const float bad : {std::numeric_limits<float>::quiet_NaN(),
                          std::numeric_limits<float>::infinity()}) {
    GltfDoc doc;
    std::vector<float> uv = {0, 0, 1, 0, 0, 1};
    uv[5] = bad;
    const int mesh =
        doc.Mesh("Tri", {{"attributes",
                          {{"POSITION", doc.Positions(kTriangle)},
                           {"TEXCOORD_0", doc.Accessor(doc.View(uv), kFloat, 3, "VEC2")}}}});
    doc.Scene({doc.Node({{"mesh", mesh}})});
    const std::string path = doc.Write(MakeTempDir("scene"), "nanuv.gltf");
    EXPECT_THAT(LoadError(path),
                HasSubstr("nanuv.gltf: mesh 'Tri' primitive 0: TEXCOORD_0 2 is not finite"));
  }
  GltfDoc doc;
  std::vector<float> xyz = kTriangle;
  for (float& v : xyz) v *= 1e30f;  // finite as float, times 1e300 overflows a double
  const int mesh = doc.Mesh("Tri", {{"attributes", {{"POSITION", doc.Positions(xyz)}}}});
  doc.Scene({doc.Node({{"mesh", mesh}, {"scale", {1e300, 1e300, 1e300}}})});
  const std::string path = doc.Write(MakeTempDir("scene"), "huge.gltf");
  EXPECT_THAT(LoadError(path), HasSubstr("huge.gltf: mesh 'Tri' primitive 0: POSITION "));
  EXPECT_THAT(LoadError(path), HasSubstr(" is not finite after the node transform"));
}

TEST(GltfSceneErrorTest, AccessorOutOfBufferBounds) {
  GltfDoc doc;
  const int view = doc.View(kTriangle);                         // 36 bytes
  const int positions = doc.Accessor(view, kFloat, 4, "VEC3");  // needs 48
  const int mesh = doc.Mesh("Tri", {{"attributes", {{"POSITION", positions}}}});
  doc.Scene({doc.Node({{"mesh", mesh}})});
  const std::string path = doc.Write(MakeTempDir("scene"), "bounds.gltf");
  EXPECT_THAT(LoadError(path),
              HasSubstr("bounds.gltf: mesh 'Tri' primitive 0: POSITION: accessor 0: "
                        "out of bounds of bufferView 0 (needs 48 bytes, has 36)"));
}

TEST(GltfSceneErrorTest, MissingImageFile) {
  GltfDoc doc;
  const std::vector<float> uv = {0, 0, 1, 0, 0, 1};
  json& d = doc.doc();
  d["images"] = {{{"uri", "gone.png"}}};
  d["textures"] = {{{"source", 0}}};
  d["materials"] = {
      {{"name", "paint"}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  const int mesh =
      doc.Mesh("Tri", {{"attributes",
                        {{"POSITION", doc.Positions(kTriangle)},
                         {"TEXCOORD_0", doc.Accessor(doc.View(uv), kFloat, 3, "VEC2")}}},
                       {"material", 0}});
  doc.Scene({doc.Node({{"mesh", mesh}})});
  const std::string path = doc.Write(MakeTempDir("scene"), "noimage.gltf");
  const std::string message = LoadError(path);
  EXPECT_THAT(message, HasSubstr("noimage.gltf: material 'paint': texture 0: image 0 'gone.png'"));
  EXPECT_THAT(message, HasSubstr("not loaded"));
}

TEST(GltfSceneErrorTest, NoTriangles) {
  GltfDoc doc;
  const std::vector<float> collinear = {0, 0, 0, 1, 0, 0, 2, 0, 0};
  const int mesh = doc.Mesh("Line", {{"attributes", {{"POSITION", doc.Positions(collinear)}}}});
  doc.Scene({doc.Node({{"mesh", mesh}})});
  const std::string path = doc.Write(MakeTempDir("scene"), "flat.gltf");
  EXPECT_THAT(LoadError(path), HasSubstr("flat.gltf: no triangles (0 points/lines primitives "
                                         "skipped, 1 degenerate triangles dropped)"));
}

TEST(GltfSceneErrorTest, OtherStructuralErrors) {
  {  // Node cycle.
    GltfDoc doc;
    const int mesh = doc.Mesh("Tri", {{"attributes", {{"POSITION", doc.Positions(kTriangle)}}}});
    doc.Node({{"name", "a"}, {"mesh", mesh}, {"children", {1}}});
    doc.Node({{"name", "b"}, {"children", {0}}});
    doc.Scene({0});
    EXPECT_THAT(LoadError(doc.Write(MakeTempDir("scene"), "cycle.gltf")),
                HasSubstr("cycle.gltf: node 'a': the node hierarchy has a cycle"));
  }
  {  // Sparse index out of range.
    GltfDoc doc;
    const int positions = doc.Accessor(doc.View(kTriangle), kFloat, 3, "VEC3");
    doc.doc()["accessors"][positions]["sparse"] = {
        {"count", 1},
        {"indices", {{"bufferView", doc.View(std::vector<uint16_t>{7})}, {"componentType", kU16}}},
        {"values", {{"bufferView", doc.View(std::vector<float>{0, 4, 0})}}}};
    doc.Scene({doc.Node({{"mesh", doc.Mesh("Tri", {{"attributes", {{"POSITION", positions}}}})}})});
    EXPECT_THAT(LoadError(doc.Write(MakeTempDir("scene"), "sparse.gltf")),
                HasSubstr("sparse.gltf: mesh 'Tri' primitive 0: POSITION: accessor 0: sparse: "
                          "index 7 out of range (3 elements)"));
  }
  {  // Unsupported required extension.
    GltfDoc doc;
    doc.Scene({doc.Node(
        {{"mesh", doc.Mesh("Tri", {{"attributes", {{"POSITION", doc.Positions(kTriangle)}}}})}})});
    doc.doc()["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    doc.doc()["extensionsUsed"] = {"KHR_draco_mesh_compression"};
    EXPECT_THAT(LoadError(doc.Write(MakeTempDir("scene"), "draco.gltf")),
                HasSubstr("draco.gltf: requires glTF extension KHR_draco_mesh_compression"));
  }
}

// ----------------------------------------------------------------------------------------
// Real sample models (../shared/data/gltf)

std::string Model(const std::string& relative) { return SharedDataDir() + "/gltf/" + relative; }

// Texture decoded by our loader equals OpenCV's own decoding of the PNG.
void ExpectTextureMatchesPng(const Texture& texture, const std::string& png_path) {
  cv::Mat png = cv::imread(png_path, cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(png.empty()) << png_path;
  cv::Mat rgba;
  if (png.channels() == 4) {
    cv::cvtColor(png, rgba, cv::COLOR_BGRA2RGBA);
  } else if (png.channels() == 3) {
    cv::cvtColor(png, rgba, cv::COLOR_BGR2RGBA);
  } else {
    cv::cvtColor(png, rgba, cv::COLOR_GRAY2RGBA);
  }
  ExpectSameTexels(texture.rgba, rgba);
}

TEST(GltfSampleModelsTest, Cube) {
  FRESCO_REQUIRE_SHARED_DATA();
  const Scene scene = LoadOk(Model("Cube/glTF/Cube.gltf"), true);
  EXPECT_EQ(scene.mesh.NumTriangles(), 12);  // 36 indices
  EXPECT_EQ(scene.dropped_degenerate, 0);
  ASSERT_EQ(scene.materials.size(), 1u);
  EXPECT_EQ(scene.materials[0].name, "Cube");
  ASSERT_EQ(scene.textures.size(), 1u);  // base colour only (metallicRoughness not loaded)
  EXPECT_EQ(scene.textures[0].rgba.size(), cv::Size(512, 512));
  ExpectTextureMatchesPng(scene.textures[0], Model("Cube/glTF/Cube_BaseColor.png"));
  Eigen::Vector3d lo, hi;
  scene.Bounds(&lo, &hi);
  EXPECT_LT((hi - lo - Eigen::Vector3d(2, 2, 2)).norm(), 1e-6);  // the 2 m cube
  EXPECT_LT((lo + hi).norm(), 1e-9);                             // recentred
  for (bool has_uv : scene.mesh.has_uv) EXPECT_TRUE(has_uv);
  // Closed: welded adjacency gives 3 neighbours per triangle.
  const MeshAdjacency adjacency = ComputeAdjacency(scene.mesh, 1e-5);
  for (int t = 0; t < 12; ++t) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(adjacency.EdgeNeighbours(t, k).size(), 1u);
  }
}

TEST(GltfSampleModelsTest, BoxTexturedGltfAndGlbAgree) {
  FRESCO_REQUIRE_SHARED_DATA();
  const Scene gltf = LoadOk(Model("BoxTextured/glTF/BoxTextured.gltf"));
  const Scene glb = LoadOk(Model("BoxTextured/glTF-Binary/BoxTextured.glb"));
  EXPECT_EQ(gltf.mesh.NumTriangles(), 12);
  EXPECT_EQ(gltf.mesh.vertices.size(), 24u);
  ASSERT_EQ(gltf.textures.size(), 1u);
  EXPECT_EQ(gltf.textures[0].rgba.size(), cv::Size(256, 256));
  ExpectTextureMatchesPng(gltf.textures[0], Model("BoxTextured/glTF/CesiumLogoFlat.png"));
  EXPECT_EQ(gltf.materials[0].base_color_texture, 0);
  // The root node's matrix turns the box (y-up to z-up); bounds are still a unit cube.
  Eigen::Vector3d lo, hi;
  gltf.Bounds(&lo, &hi);
  EXPECT_LT((hi - lo - Eigen::Vector3d(1, 1, 1)).norm(), 1e-6);
  ASSERT_EQ(glb.mesh.NumTriangles(), gltf.mesh.NumTriangles());
  ASSERT_EQ(glb.mesh.vertices.size(), gltf.mesh.vertices.size());
  for (size_t v = 0; v < gltf.mesh.vertices.size(); ++v) {
    EXPECT_EQ(glb.mesh.vertices[v], gltf.mesh.vertices[v]);
  }
  for (int t = 0; t < gltf.mesh.NumTriangles(); ++t) {
    EXPECT_EQ(glb.mesh.triangles[t], gltf.mesh.triangles[t]);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(glb.mesh.uvs[t][k], gltf.mesh.uvs[t][k]);
  }
  ASSERT_EQ(glb.textures.size(), 1u);
  ExpectSameTexels(glb.textures[0].rgba, gltf.textures[0].rgba);
}

TEST(GltfSampleModelsTest, BoxTexturedSurvivesSaveAndLoad) {
  FRESCO_REQUIRE_SHARED_DATA();
  const Scene original = LoadOk(Model("BoxTextured/glTF-Binary/BoxTextured.glb"), true);
  const std::string dir = MakeTempDir("scene");
  ASSERT_TRUE(SaveGltfScene(original, dir + "/box.gltf").ok());
  const Scene loaded = LoadOk(dir + "/box.gltf", true);
  ASSERT_EQ(loaded.mesh.NumTriangles(), original.mesh.NumTriangles());
  ASSERT_EQ(loaded.mesh.vertices.size(), original.mesh.vertices.size());
  for (size_t v = 0; v < original.mesh.vertices.size(); ++v) {
    EXPECT_LT((loaded.mesh.vertices[v] - original.mesh.vertices[v]).norm(), 1e-6);
  }
  EXPECT_EQ(loaded.mesh.triangles, original.mesh.triangles);
  EXPECT_EQ(loaded.mesh.uvs, original.mesh.uvs);
  ASSERT_EQ(loaded.textures.size(), 1u);
  ExpectSameTexels(loaded.textures[0].rgba, original.textures[0].rgba);
}

TEST(GltfSampleModelsTest, AvocadoBaseColorOnly) {
  FRESCO_REQUIRE_SHARED_DATA();
  const Scene scene = LoadOk(Model("Avocado/glTF/Avocado_baseColorOnly.gltf"));
  EXPECT_EQ(scene.mesh.NumTriangles() + scene.dropped_degenerate, 682);  // 2046 indices
  EXPECT_EQ(scene.dropped_degenerate, 0);
  ASSERT_EQ(scene.textures.size(), 1u);
  EXPECT_EQ(scene.textures[0].rgba.size(), cv::Size(2048, 2048));
  ExpectTextureMatchesPng(scene.textures[0], Model("Avocado/glTF/Avocado_baseColor.png"));
  // The avocado is ~6 cm tall.
  Eigen::Vector3d lo, hi;
  scene.Bounds(&lo, &hi);
  EXPECT_GT(hi.y() - lo.y(), 0.05);
  EXPECT_LT(hi.y() - lo.y(), 0.07);
}

TEST(GltfSampleModelsTest, CesiumMilkTruck) {
  FRESCO_REQUIRE_SHARED_DATA();
  const Scene scene = LoadOk(Model("CesiumMilkTruck/glTF/CesiumMilkTruck.gltf"), true);
  // Wheels (768 triangles) are instanced twice; truck body 1744 + glass 56 + trim 288.
  EXPECT_EQ(scene.mesh.NumTriangles() + scene.dropped_degenerate, 2 * 768 + 1744 + 56 + 288);
  EXPECT_LT(scene.dropped_degenerate, 10);
  ASSERT_EQ(scene.materials.size(), 4u);
  EXPECT_EQ(scene.materials[2].name, "glass");
  EXPECT_EQ(scene.materials[2].base_color_texture, -1);
  EXPECT_NEAR(scene.materials[3].base_color_factor[0], 0.064, 1e-6);
  ASSERT_EQ(scene.textures.size(), 2u);  // two glTF textures sharing one JPEG
  for (const Texture& texture : scene.textures) {
    EXPECT_EQ(texture.rgba.size(), cv::Size(2048, 2048));
  }
  std::vector<int> per_material(4, 0);
  for (int m : scene.mesh.material) ++per_material[m];
  EXPECT_EQ(per_material[0] + scene.dropped_degenerate, 2 * 768);  // only wheels drop any
  EXPECT_EQ(per_material[1], 1744);
  EXPECT_EQ(per_material[2], 56);
  EXPECT_EQ(per_material[3], 288);
  // World extent through the 3-level hierarchy (Yup2Zup rotation, wheel-axle translations,
  // rotated wheels), computed independently from the file with a short Python script.
  Eigen::Vector3d lo, hi;
  scene.Bounds(&lo, &hi);
  EXPECT_LT(
      (hi - lo - Eigen::Vector3d(2.791999888896939, 2.5829179724621407, 4.868909915862073)).norm(),
      1e-6);
}

}  // namespace
}  // namespace fresco
