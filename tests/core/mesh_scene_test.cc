// PLY and OBJ scenes (LoadMeshScene through Assimp) and LoadScene's choice by extension: the
// same mesh as glTF, binary PLY, ASCII PLY and OBJ gives the same triangles in the same order;
// map-scale recentring; UVs flipped to glTF's convention and MTL textures; groups, materials
// and polygons keep the file's face order; bad files are one-line errors; the real Sceaux
// meshes in ../shared/data; and `fresco run` painting a project whose scene is a PLY.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "pipeline/core/mesh_scene.h"
#include "pipeline/core/scene.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using ::fresco::testing::MakeTempDir;
using ::fresco::testing::ReadText;
using ::fresco::testing::RunFresco;
using ::fresco::testing::SharedDataDir;
using ::fresco::testing::WriteText;
using ::testing::HasSubstr;
using ::testing::StartsWith;

// Vectors as "x y z" at the stream's precision.
const Eigen::IOFormat kSpaced(Eigen::StreamPrecision, Eigen::DontAlignCols, " ", " ");

// A mesh as a file stores it: world positions, faces (any number of corners), and per-vertex
// UVs in the files' convention (v = 0 at the image's bottom) when `uvs` is not empty.
struct FileMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::vector<int>> faces;
  std::vector<Eigen::Vector2f> uvs;
};

// A 1 m cube around `centre` (8 shared vertices, 12 outward counter-clockwise triangles), then
// one degenerate triangle (a repeated corner) that every reader drops.
FileMesh Cube(const Eigen::Vector3d& centre) {
  FileMesh mesh;
  for (int i = 0; i < 8; ++i) {
    mesh.vertices.push_back(centre +
                            0.5 * Eigen::Vector3d(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1));
  }
  mesh.faces = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4}, {2, 6, 7},
                {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}, {0, 1, 1}};
  return mesh;
}

// ASCII PLY: x y z (float), optionally s t and red green blue, then the faces.
std::string AsciiPly(const FileMesh& mesh, bool colours) {
  std::ostringstream ply;
  ply.precision(9);  // exact for floats
  ply << "ply\nformat ascii 1.0\ncomment written by mesh_scene_test\nelement vertex "
      << mesh.vertices.size() << "\nproperty float x\nproperty float y\nproperty float z\n";
  if (!mesh.uvs.empty()) ply << "property float s\nproperty float t\n";
  if (colours) ply << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  ply << "element face " << mesh.faces.size()
      << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    ply << mesh.vertices[v].transpose().format(kSpaced);
    if (!mesh.uvs.empty()) ply << " " << mesh.uvs[v].transpose().format(kSpaced);
    if (colours) ply << " 200 " << v * 20 << " 7";
    ply << "\n";
  }
  for (const auto& face : mesh.faces) {
    ply << face.size();
    for (int v : face) ply << " " << v;
    ply << "\n";
  }
  return ply.str();
}

template <typename T>
void Append(std::string* bytes, T value) {  // little-endian, as the host
  bytes->append(reinterpret_cast<const char*>(&value), sizeof(T));
}

// Binary little-endian PLY: float x y z, faces as uchar count + int indices.
std::string BinaryPly(const FileMesh& mesh) {
  std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex " +
                    std::to_string(mesh.vertices.size()) +
                    "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                    std::to_string(mesh.faces.size()) +
                    "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const Eigen::Vector3d& p : mesh.vertices) {
    for (int k = 0; k < 3; ++k) Append(&ply, static_cast<float>(p[k]));
  }
  for (const auto& face : mesh.faces) {
    Append(&ply, static_cast<uint8_t>(face.size()));
    for (int v : face) Append(&ply, static_cast<int32_t>(v));
  }
  return ply;
}

// OBJ: v x y z (with r g b colours when asked), vt u v, faces 1-based (v/vt with UVs).
std::string Obj(const FileMesh& mesh, bool colours) {
  std::ostringstream obj;
  obj.precision(9);  // exact for floats
  obj << "# written by mesh_scene_test\n";
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    obj << "v " << mesh.vertices[v].transpose().format(kSpaced);
    if (colours) obj << " 0.5 0.25 " << v / 10.0;
    obj << "\n";
  }
  for (const Eigen::Vector2f& uv : mesh.uvs) obj << "vt " << uv.transpose().format(kSpaced) << "\n";
  for (const auto& face : mesh.faces) {
    obj << "f";
    for (int v : face) {
      obj << " " << v + 1;
      if (!mesh.uvs.empty()) obj << "/" << v + 1;
    }
    obj << "\n";
  }
  return obj.str();
}

// The same triangles as a Scene (SaveGltfScene writes it as glTF).
Scene SceneOf(const FileMesh& mesh) {
  Scene scene;
  scene.mesh.vertices = mesh.vertices;
  for (const auto& face : mesh.faces) {
    scene.mesh.triangles.emplace_back(face[0], face[1], face[2]);
    scene.mesh.uvs.push_back(
        {Eigen::Vector2f::Zero(), Eigen::Vector2f::Zero(), Eigen::Vector2f::Zero()});
    scene.mesh.material.push_back(0);
    scene.mesh.has_uv.push_back(false);
  }
  scene.materials.resize(1);
  return scene;
}

// LoadScene on `path`: expected to load when `error` is null, else to fail with a one-line
// message, stored in `error`.
Scene LoadOk(const std::string& path, bool recentre = true, std::string* error = nullptr) {
  SceneLoadOptions options;
  options.recentre = recentre;
  Scene scene;
  const Status status = LoadScene(path, options, &scene);
  EXPECT_EQ(status.ok(), error == nullptr) << path << ": " << status.message();
  EXPECT_EQ(status.message().find('\n'), std::string::npos) << status.message();
  if (error) *error = status.message();
  return scene;
}
std::string LoadError(const std::string& path) {
  std::string error;
  LoadOk(path, /*recentre=*/true, &error);
  return error;
}

// Same triangle count, and corner k of triangle t at the same world position.
void ExpectSameTriangles(const Scene& expected, const Scene& actual, double tolerance_m) {
  ASSERT_EQ(actual.mesh.NumTriangles(), expected.mesh.NumTriangles()) << actual.source_path;
  for (int t = 0; t < expected.mesh.NumTriangles(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d e = expected.WorldFromLocal(expected.mesh.Corner(t, k));
      const Eigen::Vector3d a = actual.WorldFromLocal(actual.mesh.Corner(t, k));
      EXPECT_LE((e - a).norm(), tolerance_m)
          << actual.source_path << " triangle " << t << " corner " << k;
    }
  }
}

// ----------------------------------------------------------------------------------------
// Same mesh, four formats

TEST(MeshSceneTest, GltfPlyBinaryPlyAsciiAndObjGiveTheSameTriangles) {
  const std::string dir = MakeTempDir("mesh-scene");
  const FileMesh cube = Cube(Eigen::Vector3d(10.0, -5.0, 2.5));
  ASSERT_TRUE(SaveGltfScene(SceneOf(cube), dir + "/cube.gltf").ok());
  WriteText(dir + "/cube_binary.ply", BinaryPly(cube));
  WriteText(dir + "/cube_ascii.ply", AsciiPly(cube, /*colours=*/true));
  WriteText(dir + "/cube.obj", Obj(cube, /*colours=*/true));

  const Scene gltf = LoadOk(dir + "/cube.gltf");
  ASSERT_EQ(gltf.mesh.NumTriangles(), 12);
  EXPECT_EQ(gltf.dropped_degenerate, 1);
  for (const char* name : {"cube_binary.ply", "cube_ascii.ply", "cube.obj"}) {
    const Scene mesh = LoadOk(dir + "/" + name);
    EXPECT_EQ(mesh.source_path, dir + "/" + name);
    EXPECT_EQ(mesh.dropped_degenerate, 1) << name;
    EXPECT_EQ(mesh.skipped_primitives, 0) << name;
    ExpectSameTriangles(gltf, mesh, 1e-6);
    EXPECT_TRUE(mesh.origin_in_world.isApprox(Eigen::Vector3d(10.0, -5.0, 2.5))) << name;
    // Outward normals: counter-clockwise stays front.
    for (int t = 0; t < mesh.mesh.NumTriangles(); ++t) {
      const Eigen::Vector3d centre =
          (mesh.mesh.Corner(t, 0) + mesh.mesh.Corner(t, 1) + mesh.mesh.Corner(t, 2)) / 3.0;
      EXPECT_GT(mesh.mesh.Normal(t).dot(centre), 0.0) << name << " triangle " << t;
    }
    ASSERT_EQ(mesh.materials.size(), 1u);
    EXPECT_EQ(mesh.materials[0].name, "default");
    EXPECT_EQ(mesh.materials[0].base_color_factor, Eigen::Vector4d::Ones());
    EXPECT_EQ(mesh.mesh.material, std::vector<int>(12, 0));
    EXPECT_EQ(mesh.mesh.has_uv, std::vector<bool>(12, false));
    EXPECT_TRUE(mesh.textures.empty());
  }
  // The PLY keeps the file's vertices and indices (nothing welded or split).
  const Scene ply = LoadOk(dir + "/cube_binary.ply", /*recentre=*/false);
  ASSERT_EQ(ply.mesh.vertices.size(), 8u);
  for (int v = 0; v < 8; ++v) EXPECT_EQ(ply.mesh.vertices[v], cube.vertices[v]);
  for (int t = 0; t < 12; ++t) {
    EXPECT_EQ(ply.mesh.triangles[t],
              Eigen::Vector3i(cube.faces[t][0], cube.faces[t][1], cube.faces[t][2]));
  }
}

TEST(MeshSceneTest, LoadSceneChoosesByExtensionIgnoringCase) {
  const std::string dir = MakeTempDir("mesh-scene");
  const FileMesh cube = Cube(Eigen::Vector3d::Zero());
  WriteText(dir + "/CUBE.PLY", BinaryPly(cube));
  WriteText(dir + "/cube.Obj", Obj(cube, false));
  EXPECT_EQ(LoadOk(dir + "/CUBE.PLY").mesh.NumTriangles(), 12);
  EXPECT_EQ(LoadOk(dir + "/cube.Obj").mesh.NumTriangles(), 12);
  WriteText(dir + "/cube.stl", "solid cube\nendsolid cube\n");
  EXPECT_EQ(LoadError(dir + "/cube.stl"),
            dir + "/cube.stl: unknown scene format '.stl' (glTF .gltf/.glb, PLY .ply or OBJ .obj)");
  EXPECT_THAT(LoadError(dir + "/noextension"), HasSubstr("unknown scene format ''"));
}

// ----------------------------------------------------------------------------------------
// Map scale

TEST(MeshSceneTest, FarFromOriginMeshRecentresWithoutLosingPrecision) {
  const std::string dir = MakeTempDir("mesh-scene");
  // Exact floats near 1e6 m (their spacing there is 1/16 m).
  const Eigen::Vector3d centre(1000000.5, -2000000.25, 300.0);
  const FileMesh cube = Cube(centre);
  WriteText(dir + "/far.ply", BinaryPly(cube));
  WriteText(dir + "/far.obj", Obj(cube, false));
  for (const char* name : {"far.ply", "far.obj"}) {
    const Scene scene = LoadOk(dir + "/" + name);
    EXPECT_EQ(scene.origin_in_world, centre) << name;
    Eigen::Vector3d lo, hi;
    scene.Bounds(&lo, &hi);
    EXPECT_EQ(lo, Eigen::Vector3d::Constant(-0.5)) << name;
    EXPECT_EQ(hi, Eigen::Vector3d::Constant(0.5)) << name;
    EXPECT_EQ(scene.mesh.NumTriangles(), 12) << name;
    const Scene kept = LoadOk(dir + "/" + name, /*recentre=*/false);
    EXPECT_EQ(kept.origin_in_world, Eigen::Vector3d::Zero());
    EXPECT_EQ(kept.mesh.Corner(0, 0), cube.vertices[0]) << name;
  }
}

// ----------------------------------------------------------------------------------------
// UVs and textures

TEST(MeshSceneTest, ObjUvsAreFlippedToGltfConventionAndMtlTextureIsRead) {
  const std::string dir = MakeTempDir("mesh-scene");
  // 2x1 RGBA texture: red on the left, translucent blue on the right.
  cv::Mat bgra(1, 2, CV_8UC4);
  bgra.at<cv::Vec4b>(0, 0) = cv::Vec4b(0, 0, 255, 255);
  bgra.at<cv::Vec4b>(0, 1) = cv::Vec4b(255, 0, 0, 128);
  fs::create_directories(dir + "/images");
  ASSERT_TRUE(cv::imwrite(dir + "/images/paint.png", bgra));
  WriteText(dir + "/quad.mtl",
            "newmtl painted\nKd 1 1 1\nmap_Kd images\\paint.png\nnewmtl plain\nKd 0.5 0.5 0.5\n");
  WriteText(dir + "/quad.obj",
            "mtllib quad.mtl\n"
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
            "vt 0 0.25\nvt 1 0.25\nvt 1 1\nvt 0 1\n"
            "usemtl painted\nf 1/1 2/2 3/3\n"
            "usemtl plain\nf 1 3 4\n");
  const Scene scene = LoadOk(dir + "/quad.obj");
  ASSERT_EQ(scene.mesh.NumTriangles(), 2);
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings[0];
  EXPECT_EQ(scene.mesh.has_uv, std::vector<bool>({true, false}));
  // v = 1 - v_obj: OBJ's v = 0.25 (a quarter up from the bottom) is glTF's 0.75.
  EXPECT_EQ(scene.mesh.uvs[0][0], Eigen::Vector2f(0.0f, 0.75f));
  EXPECT_EQ(scene.mesh.uvs[0][1], Eigen::Vector2f(1.0f, 0.75f));
  EXPECT_EQ(scene.mesh.uvs[0][2], Eigen::Vector2f(1.0f, 0.0f));
  EXPECT_EQ(scene.mesh.uvs[1][0], Eigen::Vector2f::Zero());
  ASSERT_EQ(scene.materials.size(), 2u);
  EXPECT_EQ(scene.mesh.material, std::vector<int>({1, 0}));
  EXPECT_EQ(scene.materials[1].name, "painted");
  EXPECT_EQ(scene.materials[1].base_color_factor, Eigen::Vector4d::Ones());
  ASSERT_EQ(scene.materials[1].base_color_texture, 0);
  ASSERT_EQ(scene.textures.size(), 1u);
  EXPECT_EQ(scene.textures[0].name, "paint.png");
  const cv::Mat& rgba = scene.textures[0].rgba;
  ASSERT_EQ(rgba.type(), CV_8UC4);
  EXPECT_EQ(rgba.at<cv::Vec4b>(0, 0), cv::Vec4b(255, 0, 0, 255));
  EXPECT_EQ(rgba.at<cv::Vec4b>(0, 1), cv::Vec4b(0, 0, 255, 128));

  // A texture that cannot be read: a warning, and the triangles use the default material.
  fs::remove(dir + "/images/paint.png");
  const Scene untextured = LoadOk(dir + "/quad.obj");
  EXPECT_EQ(untextured.mesh.material, std::vector<int>({0, 0}));
  EXPECT_TRUE(untextured.textures.empty());
  ASSERT_EQ(untextured.warnings.size(), 1u);
  EXPECT_THAT(untextured.warnings[0], HasSubstr("material 'painted': texture not used"));
  EXPECT_THAT(untextured.warnings[0], HasSubstr("paint.png"));
}

TEST(MeshSceneTest, PlyUvsAreFlippedToo) {
  const std::string dir = MakeTempDir("mesh-scene");
  FileMesh quad;
  quad.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  quad.faces = {{0, 1, 2}, {0, 2, 3}};
  quad.uvs = {{0, 0.25f}, {1, 0.25f}, {1, 1}, {0, 1}};
  WriteText(dir + "/quad.ply", AsciiPly(quad, /*colours=*/false));
  const Scene scene = LoadOk(dir + "/quad.ply");
  ASSERT_EQ(scene.mesh.NumTriangles(), 2);
  EXPECT_EQ(scene.mesh.has_uv, std::vector<bool>({true, true}));
  EXPECT_EQ(scene.mesh.uvs[0][1], Eigen::Vector2f(1.0f, 0.75f));
  EXPECT_EQ(scene.mesh.uvs[1][2], Eigen::Vector2f(0.0f, 0.0f));
}

// ----------------------------------------------------------------------------------------
// Face order

TEST(MeshSceneTest, ObjGroupsMaterialsAndPolygonsKeepTheFileOrder) {
  const std::string dir = MakeTempDir("mesh-scene");
  WriteText(dir + "/order.mtl", "newmtl a\nKd 1 0 0\nnewmtl b\nKd 0 1 0\n");
  // Groups and materials interleaved, a group name coming back, a quad, a pentagon, a line.
  WriteText(dir + "/order.obj",
            "mtllib order.mtl\n"
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 1.5 0\n"
            "g first\nusemtl a\nf 1 2 3\n"
            "usemtl b\nf 1 2 4\n"
            "g second\nusemtl a\nf 1 2 3 4\n"
            "l 1 2\n"
            "g first\nf 2 3 4\n"
            "usemtl b\nf 1 2 3 5 4\n");
  const Scene scene = LoadOk(dir + "/order.obj", /*recentre=*/false);
  EXPECT_EQ(scene.skipped_primitives, 1);  // the line
  // Triangle t's corners as vertex numbers of the file (1-based), found by position.
  const std::vector<Eigen::Vector3d> file_vertices = {
      {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 1.5, 0}};
  auto file_vertex = [&](int t, int k) {
    for (int v = 0; v < 5; ++v) {
      if (scene.mesh.Corner(t, k) == file_vertices[v]) return v + 1;
    }
    return 0;
  };
  ASSERT_EQ(scene.mesh.NumTriangles(), 1 + 1 + 2 + 1 + 3);
  // Triangles in file order: the first two and the fifth as written.
  EXPECT_EQ(Eigen::Vector3i(file_vertex(0, 0), file_vertex(0, 1), file_vertex(0, 2)),
            Eigen::Vector3i(1, 2, 3));
  EXPECT_EQ(Eigen::Vector3i(file_vertex(1, 0), file_vertex(1, 1), file_vertex(1, 2)),
            Eigen::Vector3i(1, 2, 4));
  EXPECT_EQ(Eigen::Vector3i(file_vertex(4, 0), file_vertex(4, 1), file_vertex(4, 2)),
            Eigen::Vector3i(2, 3, 4));
  // The quad (triangles 2-3) and the pentagon (5-7) cover their polygons, facing +z.
  auto area = [&](int first, int count) {
    double sum = 0.0;
    for (int t = first; t < first + count; ++t) {
      EXPECT_GT(scene.mesh.Normal(t).z(), 0.99) << "triangle " << t;
      sum += scene.mesh.Area(t);
    }
    return sum;
  };
  EXPECT_NEAR(area(2, 2), 1.0, 1e-12);
  EXPECT_NEAR(area(5, 3), 1.25, 1e-12);
  // One material for the whole file: no textures, so every triangle uses the default.
  EXPECT_EQ(scene.materials.size(), 1u);
}

// ----------------------------------------------------------------------------------------
// Bad files: one-line errors naming the file, never a crash

TEST(MeshSceneTest, BadFilesAreErrorsNamingTheFile) {
  const std::string dir = MakeTempDir("mesh-scene");
  const FileMesh cube = Cube(Eigen::Vector3d::Zero());
  auto expect_error = [&](const std::string& name, const std::string& what) {
    const std::string message = LoadError(dir + "/" + name);
    EXPECT_THAT(message, StartsWith(dir + "/" + name + ": ")) << message;
    EXPECT_THAT(message, HasSubstr(what)) << message;
  };
  expect_error("missing.ply", "file not found");
  expect_error("missing.obj", "file not found");

  // Truncated binary PLY: cut in the faces, in the vertices, and just before the end.
  const std::string binary = BinaryPly(cube);
  WriteText(dir + "/cut_faces.ply", binary.substr(0, binary.size() - 30));
  expect_error("cut_faces.ply", "truncated PLY: it ends in face 10 of the 13");
  WriteText(dir + "/cut_vertices.ply", binary.substr(0, binary.find("end_header") + 30));
  expect_error("cut_vertices.ply", "truncated PLY: it ends in vertex 1 of the 8");
  WriteText(dir + "/cut_last_byte.ply", binary.substr(0, binary.size() - 1));
  expect_error("cut_last_byte.ply", "truncated PLY: it ends in face 12 of the 13");
  // An absurd count in an ASCII header (Assimp would allocate for minutes).
  std::string huge = AsciiPly(cube, false);
  huge.replace(huge.find("element vertex 8"), 16, "element vertex 4000000000");
  WriteText(dir + "/huge.ply", huge);
  const auto start = std::chrono::steady_clock::now();
  expect_error("huge.ply", "truncated PLY");
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1));

  // Garbage, empty files, and text that is not a mesh.
  WriteText(dir + "/garbage.ply", "this is not a mesh\n\x01\x02\x03");
  expect_error("garbage.ply", "cannot read PLY: Invalid .ply file: Incorrect magic number");
  WriteText(dir + "/empty.ply", "");
  expect_error("empty.ply", "cannot read PLY");
  WriteText(dir + "/garbage.obj", "this is not a mesh\n\x01\x02\x03");
  expect_error("garbage.obj", "no triangles (0 point/line faces skipped");
  WriteText(dir + "/empty.obj", "");
  expect_error("empty.obj", "cannot read OBJ");

  // Face indices out of range (ASCII and binary PLY, OBJ).
  FileMesh bad = cube;
  bad.faces[4] = {0, 1, 99};
  WriteText(dir + "/index_ascii.ply", AsciiPly(bad, false));
  expect_error("index_ascii.ply", "face 4: vertex 99 out of range (8 vertices)");
  WriteText(dir + "/index_binary.ply", BinaryPly(bad));
  expect_error("index_binary.ply", "face 4: vertex 99 out of range (8 vertices)");
  WriteText(dir + "/index.obj", Obj(bad, false));
  expect_error("index.obj", "cannot read OBJ: OBJ: vertex index out of range");

  // Non-finite coordinates.
  std::string nan_ply = AsciiPly(cube, false);
  nan_ply.replace(nan_ply.find("end_header\n") + 11, 4, "nan ");
  WriteText(dir + "/nan.ply", nan_ply);
  expect_error("nan.ply", "vertex 0 is not finite");
  WriteText(dir + "/inf.obj", "v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n");
  expect_error("inf.obj", "vertex 1 is not finite");

  // A point cloud (no faces) and a mesh of only degenerate triangles.
  FileMesh points = cube;
  points.faces.clear();
  WriteText(dir + "/points.ply", AsciiPly(points, false));
  expect_error("points.ply", "no triangles");
  WriteText(dir + "/flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
  expect_error("flat.obj", "no triangles (0 point/line faces skipped, 1 degenerate");
}

// ----------------------------------------------------------------------------------------
// The real meshes: OpenMVS's reconstruction of the Sceaux castle (binary PLY)

TEST(MeshSceneTest, RealSceauxMeshesLoadWithEveryFace) {
  FRESCO_REQUIRE_SHARED_DATA();
  const std::string dir = SharedDataDir() + "/sceaux-castle-openmvs/openmvs_original";
  if (!fs::is_directory(dir)) GTEST_SKIP() << dir << " is absent: skipped";
  for (const auto& [name, faces] : std::vector<std::pair<std::string, int>>{
           {"scene_mesh_refine.ply", 174899}, {"scene_mesh.ply", 14709}}) {
    const auto start = std::chrono::steady_clock::now();
    const Scene scene = LoadOk(dir + "/" + name);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("[ info     ] %s: %d triangles in %.3f s\n", name.c_str(),
                scene.mesh.NumTriangles(), seconds);
    EXPECT_EQ(scene.mesh.NumTriangles(), faces) << name;
    EXPECT_EQ(scene.dropped_degenerate, 0) << name;
    EXPECT_LT(seconds, 5.0) << name;
    Eigen::Vector3d lo, hi;
    scene.Bounds(&lo, &hi);
    EXPECT_TRUE((lo + hi).isZero(1e-9)) << name;  // recentred on the bounding box
    EXPECT_GT((hi - lo).norm(), 1.0) << name;
  }
}

// The two scenes alike in everything LoadMeshScene fills.
void ExpectSameScene(const Scene& a, const Scene& b, const std::string& what) {
  EXPECT_EQ(a.mesh.vertices, b.mesh.vertices) << what;
  EXPECT_EQ(a.mesh.triangles, b.mesh.triangles) << what;
  EXPECT_EQ(a.mesh.material, b.mesh.material) << what;
  EXPECT_EQ(a.mesh.has_uv, b.mesh.has_uv) << what;
  ASSERT_EQ(a.mesh.uvs.size(), b.mesh.uvs.size()) << what;
  for (size_t t = 0; t < a.mesh.uvs.size(); ++t)
    for (int k = 0; k < 3; ++k) ASSERT_EQ(a.mesh.uvs[t][k], b.mesh.uvs[t][k]) << what << " " << t;
  EXPECT_EQ(a.origin_in_world, b.origin_in_world) << what;
  EXPECT_EQ(a.materials.size(), b.materials.size()) << what;
  EXPECT_EQ(a.dropped_degenerate, b.dropped_degenerate) << what;
  EXPECT_EQ(a.skipped_primitives, b.skipped_primitives) << what;
}

// A plain binary PLY (OpenMVS's kind) is read without Assimp into exactly the scene Assimp
// gives: the real Sceaux meshes, and a cube with more vertex properties (normals, colours, a
// double), an unused vertex and a degenerate triangle. A file of another kind (a polygon, a
// texture) goes through Assimp as before; a truncated one is still refused, naming where.
TEST(MeshSceneTest, PlainBinaryPlyIsReadAsAssimpReadsIt) {
  const std::string dir = MakeTempDir("mesh-scene-plain-ply");
  FileMesh cube = Cube(Eigen::Vector3d(3.5, -2.25, 1));
  cube.vertices.push_back(Eigen::Vector3d(9, 9, 9));  // used by no face
  std::string ply =
      "ply\nformat binary_little_endian 1.0\ncomment OpenMVS\nelement vertex " +
      std::to_string(cube.vertices.size()) +
      "\nproperty double confidence\nproperty float x\nproperty float y\nproperty float z\n"
      "property float nx\nproperty float ny\nproperty float nz\nproperty uchar red\n"
      "property uchar green\nproperty uchar blue\nelement face " +
      std::to_string(cube.faces.size()) +
      "\nproperty list uint8 uint32 vertex_indices\nend_header\n";
  for (size_t v = 0; v < cube.vertices.size(); ++v) {
    Append(&ply, 0.25 * v);
    for (int k = 0; k < 3; ++k) Append(&ply, static_cast<float>(cube.vertices[v][k]));
    for (int k = 0; k < 3; ++k) Append(&ply, 0.5f);
    for (int k = 0; k < 3; ++k) Append(&ply, static_cast<uint8_t>(40 * k + v));
  }
  for (const auto& face : cube.faces) {
    Append(&ply, static_cast<uint8_t>(3));
    for (int v : face) Append(&ply, static_cast<uint32_t>(v));
  }
  std::vector<std::string> files = {dir + "/extra.ply"};
  WriteText(files.back(), ply);
  files.push_back(dir + "/plain.ply");
  WriteText(files.back(), BinaryPly(Cube(Eigen::Vector3d(0, 0, 0))));
  FileMesh polygon = Cube(Eigen::Vector3d(0, 0, 0));
  polygon.faces.push_back({0, 1, 3, 2});
  files.push_back(dir + "/polygon.ply");
  WriteText(files.back(), BinaryPly(polygon));
  const std::string shared = SharedDataDir() + "/sceaux-castle-openmvs/openmvs_original";
  for (const char* name : {"scene_mesh_refine.ply", "scene_mesh.ply"})
    if (fs::exists(shared + "/" + name)) files.push_back(shared + "/" + name);
  for (const std::string& file : files) {
    Scene plain, assimp;
    ASSERT_TRUE(LoadMeshScene(file, SceneLoadOptions(), &plain).ok()) << file;
    ASSERT_TRUE(LoadMeshSceneThroughAssimp(file, SceneLoadOptions(), &assimp).ok()) << file;
    EXPECT_GT(plain.mesh.NumTriangles(), 0) << file;
    ExpectSameScene(plain, assimp, file);
  }
  WriteText(dir + "/short.ply", ply.substr(0, ply.size() - 5));
  EXPECT_THAT(LoadError(dir + "/short.ply"), HasSubstr("truncated PLY: it ends in face 12"));
}

// ----------------------------------------------------------------------------------------
// `fresco run` on a project whose scene is a PLY

TEST(MeshSceneTest, RunPaintsAPlySceneAsItsGltf) {
  const std::string dir = MakeTempDir("mesh-scene-run");
  const std::string capture = dir + "/capture";
  const auto synth = RunFresco({"synth", "--scene", "builtin:cube-room", "--out", capture,
                                "--frames", "6", "--size", "160x120", "--seed", "3"});
  ASSERT_EQ(synth.exit_code, 0) << synth.err;
  // The same room as a binary PLY (no UVs: painting does not need the model's own).
  const Scene gltf = LoadOk(capture + "/scene.gltf", /*recentre=*/false);
  FileMesh room;
  for (const Eigen::Vector3d& v : gltf.mesh.vertices) room.vertices.push_back(v);
  for (const Eigen::Vector3i& t : gltf.mesh.triangles) room.faces.push_back({t[0], t[1], t[2]});
  WriteText(capture + "/scene.ply", BinaryPly(room));
  nlohmann::json project = nlohmann::json::parse(ReadText(capture + "/project.json"));
  ASSERT_EQ(project["scene"], "scene.gltf");
  project["scene"] = "scene.ply";
  WriteText(capture + "/project_ply.json", project.dump(2));

  nlohmann::json metrics[2];
  const char* projects[2] = {"/project.json", "/project_ply.json"};
  for (int i = 0; i < 2; ++i) {
    const std::string out = dir + "/out" + std::to_string(i);
    const auto run = RunFresco({"run", capture + projects[i], "--out", out, "--quiet"});
    ASSERT_EQ(run.exit_code, 0) << run.err;
    metrics[i] = nlohmann::json::parse(ReadText(out + "/metrics.json"));
  }
  EXPECT_EQ(metrics[1]["frames_painted"], metrics[0]["frames_painted"]);
  EXPECT_EQ(metrics[1]["base_buffers"], metrics[0]["base_buffers"]);
  EXPECT_EQ(metrics[1]["texels"], metrics[0]["texels"]);
  EXPECT_GT(metrics[0]["coverage"].get<double>(), 0.1);
  EXPECT_NEAR(metrics[1]["coverage"].get<double>(), metrics[0]["coverage"].get<double>(), 1e-9);

  // A bad PLY scene is exit code 2 naming it.
  WriteText(capture + "/scene.ply", BinaryPly(room).substr(0, 200));
  const auto bad = RunFresco({"run", capture + "/project_ply.json", "--out", dir + "/bad"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_THAT(bad.err, HasSubstr("scene.ply: truncated PLY")) << bad.err;
}

}  // namespace
}  // namespace fresco
