// `fresco render` end to end: a tiny scene written with SaveGltfScene, COLMAP cameras.txt /
// images.txt and a TUM trajectory written as text, the real binary run on them; and bad input
// giving exit code 2 with a one-line message naming the file.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/cameramodel_io.h"
#include "pipeline/core/poses.h"
#include "pipeline/core/scene.h"
#include "pipeline/render/renderer.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using testing::CommandResult;
using testing::RunFresco;
using testing::WriteText;

// A textured quad 2 m in front of the identity pose (world z forward, y down, so the camera
// frame equals the world frame), its texture's right half unpainted (alpha 0); and an
// untextured red triangle in the lower left.
Scene MakeScene() {
  Scene scene;
  Texture texture;
  texture.rgba = cv::Mat(16, 16, CV_8UC4, cv::Scalar(30, 140, 220, 255));
  texture.rgba.colRange(8, 16).setTo(cv::Scalar(255, 0, 255, 0));
  texture.wrap_s = texture.wrap_t = TextureWrap::kClampToEdge;
  texture.name = "paint";
  scene.textures.push_back(texture);
  Material textured;
  textured.base_color_texture = 0;
  textured.name = "textured";
  Material red;
  red.base_color_factor = Eigen::Vector4d(1.0, 0.0, 0.0, 1.0);
  red.name = "red";
  scene.materials = {textured, red};
  TriangleMesh& mesh = scene.mesh;
  // Quad facing -z (towards the camera): counter-clockwise seen from the camera.
  mesh.vertices = {{-0.6, -0.4, 2.0}, {-0.6, 0.4, 2.0}, {0.6, 0.4, 2.0}, {0.6, -0.4, 2.0},
                   {-1.0, 0.5, 1.9},  {-1.0, 0.7, 1.9}, {-0.7, 0.7, 1.9}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}};
  const Eigen::Vector2f t00(0, 0), t01(0, 1), t11(1, 1), t10(1, 0);
  mesh.uvs = {{t00, t01, t11}, {t00, t11, t10}, {t00, t00, t00}};
  mesh.material = {0, 0, 1};
  mesh.has_uv = {true, true, false};
  return scene;
}

struct Fixture {
  std::string dir, model, cameras, images, tum, out;
};

Fixture WriteFixture() {
  Fixture f;
  f.dir = testing::MakeTempDir("render-cmd");
  f.model = f.dir + "/scene/scene.gltf";
  fs::create_directories(f.dir + "/scene");
  const Status saved = SaveGltfScene(MakeScene(), f.model);
  EXPECT_TRUE(saved.ok()) << saved.message();
  f.cameras = f.dir + "/sparse/cameras.txt";
  // Camera 1: pinhole 64x48, principal point at the image centre in COLMAP's convention.
  // Camera 2: a distorted one at another size.
  WriteText(f.cameras,
            "# Camera list\n"
            "1 PINHOLE 64 48 60 60 32 24\n"
            "2 OPENCV 40 30 36 36 20 15 -0.2 0.03 0.001 -0.001\n");
  f.images = f.dir + "/sparse/images.txt";
  WriteText(f.images,
            "# Image list\n"
            "1 1 0 0 0 0 0 0 1 frames/a.jpg\n"
            "\n"
            "2 0.9990482 0 0.0436194 0 0 0 0 2 b.png\n"
            "10 20 -1\n");
  f.tum = f.dir + "/poses.tum";
  WriteText(f.tum,
            "# timestamp tx ty tz qx qy qz qw\n"
            "0.0 0 0 0 0 0 0 1\n"
            "0.1 0.05 0 -0.2 0 0 0 1\n");
  f.out = f.dir + "/out";
  return f;
}

cv::Mat ReadRgba(const std::string& path) {
  cv::Mat bgra = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (bgra.empty() || bgra.type() != CV_8UC4) return cv::Mat();
  cv::Mat rgba;
  cv::cvtColor(bgra, rgba, cv::COLOR_BGRA2RGBA);
  return rgba;
}

int CountFiles(const std::string& dir) {
  if (!fs::exists(dir)) return 0;
  int n = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) n += entry.is_regular_file();
  return n;
}

TEST(RenderCommandTest, ColmapPosesWriteOnePngPerImage) {
  const Fixture f = WriteFixture();
  const CommandResult r = RunFresco({"render", f.model, "--camera", f.cameras, "--poses", f.images,
                                     "--out", f.out, "--depth", "--ids"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // NAME's extension replaced by .png, subfolders created.
  const cv::Mat a = ReadRgba(f.out + "/frames/a.png");
  const cv::Mat b = ReadRgba(f.out + "/b.png");
  ASSERT_FALSE(a.empty());
  ASSERT_FALSE(b.empty());
  EXPECT_EQ(a.size(), cv::Size(64, 48));
  EXPECT_EQ(b.size(), cv::Size(40, 30));
  EXPECT_FALSE(fs::exists(f.out + "/frames/a.jpg"));

  // Camera 1 (identity pose): cx = 31.5 after the COLMAP shift, f = 60; the quad spans
  // x in [-0.6, 0.6] at z = 2, i.e. pixels 31.5 +- 18. Its left half is painted.
  EXPECT_EQ(a.at<cv::Vec4b>(24, 20), cv::Vec4b(30, 140, 220, 255));
  EXPECT_EQ(a.at<cv::Vec4b>(24, 40)[3], 0);                 // unpainted half: alpha 0 ...
  EXPECT_EQ(a.at<cv::Vec4b>(2, 2), cv::Vec4b(0, 0, 0, 0));  // ... and background
  // The red triangle (x -1.0..-0.7, y 0.5..0.7 at z = 1.9): pixels ~0..9, 40..46.
  EXPECT_EQ(a.at<cv::Vec4b>(45, 2), cv::Vec4b(255, 0, 0, 255));
  std::vector<cv::Mat> channels;
  cv::split(a, channels);
  const int opaque = cv::countNonZero(channels[3]);
  EXPECT_GT(opaque, 250);  // ~18 x 24 painted quad half + the triangle
  EXPECT_LT(opaque, 600);
  // Alpha is strictly 0 or 255.
  EXPECT_EQ(cv::countNonZero((channels[3] != 0) & (channels[3] != 255)), 0);

  // Same pixels as rendering in-process with the files read back.
  Scene scene;
  ASSERT_TRUE(LoadGltfScene(f.model, SceneLoadOptions(), &scene).ok());
  std::map<int, Camera> cameras;
  ASSERT_TRUE(ReadCameras(f.cameras, &cameras).ok());
  std::vector<PosedImage> poses;
  bool is_tum = true;
  ASSERT_TRUE(ReadPoses(f.images, &poses, &is_tum).ok());
  ASSERT_FALSE(is_tum);
  ASSERT_EQ(poses.size(), 2u);
  RenderOutput expected_a, expected;
  Renderer(cameras.at(1), RenderOptions()).Render(scene, poses[0].cam_from_world, &expected_a);
  Renderer(cameras.at(2), RenderOptions()).Render(scene, poses[1].cam_from_world, &expected);
  EXPECT_EQ(cv::countNonZero(cv::Mat(a != expected_a.rgba).reshape(1)), 0);
  EXPECT_EQ(cv::countNonZero(cv::Mat(b != expected.rgba).reshape(1)), 0);
  cv::split(b, channels);
  EXPECT_GT(cv::countNonZero(channels[3]), 20);

  // --depth: 16-bit millimetres; --ids: triangle id + 1.
  const cv::Mat depth = cv::imread(f.out + "/frames/a.depth.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(depth.type(), CV_16U);
  EXPECT_EQ(depth.at<uint16_t>(24, 20), 2000);
  EXPECT_EQ(depth.at<uint16_t>(24, 40), 2000);  // unpainted, but a surface
  EXPECT_EQ(depth.at<uint16_t>(2, 2), 0);
  const cv::Mat ids = ReadRgba(f.out + "/frames/a.ids.png");
  ASSERT_FALSE(ids.empty());
  const cv::Vec4b id_red = ids.at<cv::Vec4b>(45, 2);
  EXPECT_EQ(id_red[0] + 256 * id_red[1] + 65536 * id_red[2] - 1,
            expected_a.triangle_id.at<int>(45, 2));
  EXPECT_GE(expected_a.triangle_id.at<int>(45, 2), 0);
  EXPECT_EQ(ids.at<cv::Vec4b>(2, 2), cv::Vec4b(0, 0, 0, 0));
  EXPECT_EQ(CountFiles(f.out), 6);
}

TEST(RenderCommandTest, TumPosesAreNumberedInOrder) {
  const Fixture f = WriteFixture();
  WriteText(f.dir + "/one.txt", "1 PINHOLE 64 48 60 60 32 24\n");
  const CommandResult r =
      RunFresco({"render", f.model, "--camera", f.dir + "/one.txt", "--poses", f.tum, "--out",
                 f.out, "--supersample", "2", "--filter", "nearest", "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const cv::Mat first = ReadRgba(f.out + "/000000.png");
  const cv::Mat second = ReadRgba(f.out + "/000001.png");
  ASSERT_FALSE(first.empty());
  ASSERT_FALSE(second.empty());
  EXPECT_EQ(first.size(), cv::Size(64, 48));
  EXPECT_EQ(first.at<cv::Vec4b>(24, 20), cv::Vec4b(30, 140, 220, 255));
  // The second camera sits 5 cm to the right and 20 cm back: the image differs.
  EXPECT_GT(cv::countNonZero(cv::Mat(first != second).reshape(1)), 50);
  EXPECT_EQ(CountFiles(f.out), 2);
  // Deterministic: a second run writes identical files.
  const CommandResult again =
      RunFresco({"render", f.model, "--camera", f.dir + "/one.txt", "--poses", f.tum, "--out",
                 f.dir + "/out2", "--supersample", "2", "--filter", "nearest", "--quiet"});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(testing::ReadText(f.out + "/000001.png"),
            testing::ReadText(f.dir + "/out2/000001.png"));
}

TEST(RenderCommandTest, HelpAndUsage) {
  const CommandResult help = RunFresco({"render", "--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("fresco render MODEL --camera CAMERA --poses POSES --out DIR"),
            std::string::npos);
  const CommandResult missing = RunFresco({"render", "x.gltf", "--camera", "c.txt"});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("--poses"), std::string::npos) << missing.err;
}

// One line on stderr, naming `needle` (the file), exit code 2, and no image written.
void ExpectBadInput(const std::vector<std::string>& args, const std::string& needle,
                    const std::string& out_dir) {
  const CommandResult r = RunFresco(args);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(needle), std::string::npos) << "stderr: " << r.err;
  EXPECT_FALSE(r.err.empty());
  EXPECT_EQ(CountFiles(out_dir), 0) << r.err;
}

TEST(RenderCommandTest, BadInputExitsTwoNamingTheFile) {
  const Fixture f = WriteFixture();
  auto args = [&](const std::string& model, const std::string& camera, const std::string& poses) {
    return std::vector<std::string>{"render",  model, "--camera", camera,
                                    "--poses", poses, "--out",    f.out};
  };
  // Missing files.
  ExpectBadInput(args(f.dir + "/nope.gltf", f.cameras, f.images), "nope.gltf", f.out);
  ExpectBadInput(args(f.model, f.dir + "/nope.txt", f.images), "nope.txt", f.out);
  ExpectBadInput(args(f.model, f.cameras, f.dir + "/nope_images.txt"), "nope_images.txt", f.out);
  // A model that is not glTF.
  WriteText(f.dir + "/broken.gltf", "{ this is not json");
  ExpectBadInput(args(f.dir + "/broken.gltf", f.cameras, f.images), "broken.gltf", f.out);
  // Camera file with a bad model / bad value.
  WriteText(f.dir + "/bad_cameras.txt", "1 PINHOLE 64 48 -60 60 32 24\n");
  ExpectBadInput(args(f.model, f.dir + "/bad_cameras.txt", f.images), "bad_cameras.txt", f.out);
  WriteText(f.dir + "/weird_cameras.txt", "1 FISHEYE_WHATEVER 64 48 60 60 32 24\n");
  ExpectBadInput(args(f.model, f.dir + "/weird_cameras.txt", f.images), "weird_cameras.txt", f.out);
  // An image whose CAMERA_ID is not among several cameras.
  WriteText(f.dir + "/images_cam9.txt", "1 1 0 0 0 0 0 0 9 a.jpg\n\n");
  ExpectBadInput(args(f.model, f.cameras, f.dir + "/images_cam9.txt"), "images_cam9.txt", f.out);
  // Garbage poses, NaN pose, a NAME escaping the output folder, duplicate outputs.
  WriteText(f.dir + "/garbage.txt", "hello world\n");
  ExpectBadInput(args(f.model, f.cameras, f.dir + "/garbage.txt"), "garbage.txt", f.out);
  WriteText(f.dir + "/nan.txt", "0.0 nan 0 0 0 0 0 1\n");
  ExpectBadInput(args(f.model, f.cameras, f.dir + "/nan.txt"), "nan.txt", f.out);
  WriteText(f.dir + "/escape.txt", "1 1 0 0 0 0 0 0 1 ../../evil.jpg\n\n");
  ExpectBadInput(args(f.model, f.cameras, f.dir + "/escape.txt"), "escape.txt", f.out);
  WriteText(f.dir + "/dupes.txt", "1 1 0 0 0 0 0 0 1 a.jpg\n\n2 1 0 0 0 0 0 0 1 a.png\n\n");
  ExpectBadInput(args(f.model, f.cameras, f.dir + "/dupes.txt"), "dupes.txt", f.out);
  WriteText(f.dir + "/empty.txt", "# nothing\n");
  ExpectBadInput(args(f.model, f.cameras, f.dir + "/empty.txt"), "empty.txt", f.out);
  // Bad options.
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = args(f.model, f.cameras, f.images);
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  ExpectBadInput(with({"--supersample", "9"}), "--supersample", f.out);
  ExpectBadInput(with({"--filter", "cubic"}), "--filter", f.out);
  ExpectBadInput(with({"--near", "-1"}), "--near", f.out);
  // --out is an existing file.
  WriteText(f.dir + "/a_file", "x");
  const CommandResult r = RunFresco(
      {"render", f.model, "--camera", f.cameras, "--poses", f.images, "--out", f.dir + "/a_file"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("a_file"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace fresco
