// COLMAP text models: round trips of cameras.txt / images.txt / points3D.txt, the 0.5 pixel
// shift, empty 2D-point lines, strict errors with line numbers, and a real COLMAP export.
#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pipeline/core/poses.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

std::map<int, Camera> EveryColmapModel() {
  std::map<int, Camera> cameras;
  cameras[1] = Camera::FromParams(LensModel::kSimplePinhole, 640, 480, {500.25, 319.5, 239.5});
  cameras[2] = Camera::FromParams(LensModel::kColmapPinhole, 1416, 1064,
                                  {1492.6641714577, 1490.1, 725.8179316289, 562.2669694372});
  cameras[3] =
      Camera::FromParams(LensModel::kSimpleRadial, 800, 600, {610.5, 400.1, 299.7, -0.031});
  cameras[4] =
      Camera::FromParams(LensModel::kRadial, 800, 600, {610.5, 400.1, 299.7, -0.03, 0.004});
  cameras[7] = Camera::FromParams(LensModel::kColmapOpenCV, 1280, 960,
                                  {1100.1, 1105.2, 645.3, 478.4, -0.25, 0.09, 8e-4, -5e-4});
  cameras[12] = Camera::FromParams(
      LensModel::kFullOpenCV, 1280, 960,
      {1100.1, 1105.2, 645.3, 478.4, -0.25, 0.09, 8e-4, -5e-4, -0.015, 0.012, -0.004, 7e-4});
  return cameras;
}

PosedImage MakeImage(int id, int camera_id, const std::string& name, int num_points) {
  PosedImage image;
  image.image_id = id;
  image.camera_id = camera_id;
  image.name = name;
  image.cam_from_world = Rigid3d(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.3 * id + 0.1, Eigen::Vector3d(1, 2, 3).normalized())),
      Eigen::Vector3d(0.1 * id, -2.0 / 3.0, 1e6 + id / 7.0));
  for (int i = 0; i < num_points; ++i) {
    image.points2d.emplace_back(10.25 * i + 1.0 / 3.0, 5.5 * i);
    image.point3d_ids.push_back(i % 2 ? -1 : 1000 + i);
  }
  return image;
}

void ExpectSameCamera(const Camera& a, const Camera& b) {
  EXPECT_EQ(a.model, b.model);
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  const std::vector<double> pa = a.Params(), pb = b.Params();
  ASSERT_EQ(pa.size(), pb.size());
  for (size_t i = 0; i < pa.size(); ++i) EXPECT_DOUBLE_EQ(pa[i], pb[i]) << "param " << i;
}

void ExpectSameImage(const PosedImage& a, const PosedImage& b) {
  EXPECT_EQ(a.image_id, b.image_id);
  EXPECT_EQ(a.camera_id, b.camera_id);
  EXPECT_EQ(a.name, b.name);
  EXPECT_NEAR(a.cam_from_world.rotation.angularDistance(b.cam_from_world.rotation), 0, 1e-15);
  EXPECT_EQ(a.cam_from_world.translation, b.cam_from_world.translation);
  ASSERT_EQ(a.points2d.size(), b.points2d.size());
  for (size_t i = 0; i < a.points2d.size(); ++i) {
    EXPECT_DOUBLE_EQ(a.points2d[i].x(), b.points2d[i].x());
    EXPECT_DOUBLE_EQ(a.points2d[i].y(), b.points2d[i].y());
  }
  EXPECT_EQ(a.point3d_ids, b.point3d_ids);
}

std::string ReadImagesError(const std::string& text) {
  const std::string path = testing::MakeTempDir("colmap") + "/images.txt";
  testing::WriteText(path, text);
  std::vector<PosedImage> images;
  const Status status = ReadColmapImages(path, &images);
  EXPECT_FALSE(status.ok());
  // Messages start with the file's path; the tests below check what follows.
  EXPECT_THAT(status.message(), StartsWith(path + ":"));
  return status.message().substr(path.size() - std::string("images.txt").size());
}

std::string ReadCamerasError(const std::string& text) {
  const std::string path = testing::MakeTempDir("colmap") + "/cameras.txt";
  testing::WriteText(path, text);
  std::map<int, Camera> cameras;
  const Status status = ReadColmapCameras(path, &cameras);
  EXPECT_FALSE(status.ok());
  EXPECT_THAT(status.message(), StartsWith(path + ":"));
  return status.message().substr(path.size() - std::string("cameras.txt").size());
}

const char kPose[] = "0.5 0.5 0.5 0.5 1 2 3";

TEST(ColmapTextTest, CamerasRoundTripEveryModel) {
  const std::string dir = testing::MakeTempDir("colmap");
  const std::map<int, Camera> cameras = EveryColmapModel();
  ASSERT_TRUE(WriteColmapCameras(dir + "/cameras.txt", cameras).ok());
  std::map<int, Camera> read;
  const Status status = ReadColmapCameras(dir + "/cameras.txt", &read);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(read.size(), cameras.size());
  for (const auto& [id, camera] : cameras) ExpectSameCamera(read.at(id), camera);
  // Writing what was read gives the same text.
  ASSERT_TRUE(WriteColmapCameras(dir + "/again.txt", read).ok());
  EXPECT_EQ(testing::ReadText(dir + "/again.txt"), testing::ReadText(dir + "/cameras.txt"));
}

TEST(ColmapTextTest, PrincipalPointShiftsByHalfAPixel) {
  const std::string dir = testing::MakeTempDir("colmap");
  testing::WriteText(dir + "/cameras.txt", "# c\n1 PINHOLE 640 480 500 501 320 240\n");
  std::map<int, Camera> cameras;
  ASSERT_TRUE(ReadColmapCameras(dir + "/cameras.txt", &cameras).ok());
  const Camera& camera = cameras.at(1);
  EXPECT_EQ(camera.fx, 500);
  EXPECT_EQ(camera.fy, 501);
  EXPECT_EQ(camera.cx, 319.5);
  EXPECT_EQ(camera.cy, 239.5);
  ASSERT_TRUE(WriteColmapCameras(dir + "/out.txt", cameras).ok());
  EXPECT_THAT(testing::ReadText(dir + "/out.txt"),
              HasSubstr("\n1 PINHOLE 640 480 500 501 320 240\n"));

  // 2D points too.
  testing::WriteText(dir + "/images.txt", std::string("1 ") + kPose + " 1 a.png\n0.5 10.5 -1\n");
  std::vector<PosedImage> images;
  ASSERT_TRUE(ReadColmapImages(dir + "/images.txt", &images).ok());
  ASSERT_EQ(images[0].points2d.size(), 1u);
  EXPECT_EQ(images[0].points2d[0], Eigen::Vector2d(0, 10));
}

TEST(ColmapTextTest, MrcalModelsAreWrittenAsTheirColmapEquivalent) {
  const std::string dir = testing::MakeTempDir("colmap");
  std::map<int, Camera> cameras;
  cameras[1] = Camera::FromParams(
      LensModel::kOpenCV8, 1280, 960,
      {1100, 1105, 645, 478, -0.25, 0.09, 8e-4, -5e-4, -0.015, 0.012, -0.004, 7e-4});
  cameras[2] = Camera::FromParams(LensModel::kPinhole, 640, 480, {500, 500, 319.5, 239.5});
  ASSERT_TRUE(WriteColmapCameras(dir + "/cameras.txt", cameras).ok());
  std::map<int, Camera> read;
  ASSERT_TRUE(ReadColmapCameras(dir + "/cameras.txt", &read).ok());
  EXPECT_EQ(read.at(1).model, LensModel::kFullOpenCV);
  EXPECT_EQ(read.at(1).Params(), cameras.at(1).Params());
  EXPECT_EQ(read.at(2).model, LensModel::kColmapPinhole);
  EXPECT_EQ(read.at(2).Params(), cameras.at(2).Params());
}

TEST(ColmapTextTest, ModelRoundTrip) {
  const std::string dir = testing::MakeTempDir("colmap") + "/sparse/0";
  ColmapModel model;
  model.cameras = EveryColmapModel();
  model.images = {MakeImage(1, 1, "frames/000000.png", 3), MakeImage(2, 12, "b.jpg", 0),
                  MakeImage(5, 7, "name with spaces.png", 1)};
  Point3D point;
  point.id = 1000;
  point.xyz = Eigen::Vector3d(1.0 / 3.0, -2e6, 0.1);
  point.rgb = Eigen::Vector3i(255, 0, 17);
  point.error = 0.25;
  point.track = {{1, 0}, {5, 0}};
  Point3D lonely;
  lonely.id = 1002;
  model.points = {point, lonely};
  ASSERT_TRUE(WriteColmapModel(dir, model).ok());

  ColmapModel read;
  const Status status = ReadColmapModel(dir, &read);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(read.cameras.size(), model.cameras.size());
  for (const auto& [id, camera] : model.cameras) ExpectSameCamera(read.cameras.at(id), camera);
  ASSERT_EQ(read.images.size(), model.images.size());
  for (size_t i = 0; i < model.images.size(); ++i) ExpectSameImage(read.images[i], model.images[i]);
  ASSERT_EQ(read.points.size(), 2u);
  EXPECT_EQ(read.points[0].id, point.id);
  EXPECT_EQ(read.points[0].xyz, point.xyz);
  EXPECT_EQ(read.points[0].rgb, point.rgb);
  EXPECT_EQ(read.points[0].error, point.error);
  EXPECT_EQ(read.points[0].track, point.track);
  EXPECT_TRUE(read.points[1].track.empty());

  // The image with no points has an empty points line (not a separator).
  const std::string text = testing::ReadText(dir + "/images.txt");
  EXPECT_THAT(text, HasSubstr(" 12 b.jpg\n\n5 "));
  // Full precision: the text of a re-write is identical.
  const std::string again = testing::MakeTempDir("colmap") + "/again";
  ASSERT_TRUE(WriteColmapModel(again, read).ok());
  for (const char* file : {"/cameras.txt", "/images.txt", "/points3D.txt"}) {
    EXPECT_EQ(testing::ReadText(again + file), testing::ReadText(dir + file)) << file;
  }
}

TEST(ColmapTextTest, EmptyPointsLineIsNotASeparator) {
  // Image 1 has no points (empty line), image 2 follows at once; image 3's points line is
  // missing at the end of the file. A blank line between entries is tolerated.
  const std::string dir = testing::MakeTempDir("colmap");
  testing::WriteText(dir + "/images.txt", std::string("# header\n") + "1 " + kPose +
                                              " 1 a.png\n"
                                              "\n"
                                              "2 " +
                                              kPose +
                                              " 1 b.png\n"
                                              "10 20 7 30 40 -1\n"
                                              "\n"
                                              "3 " +
                                              kPose + " 1 c.png");
  std::vector<PosedImage> images;
  const Status status = ReadColmapImages(dir + "/images.txt", &images);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(images.size(), 3u);
  EXPECT_EQ(images[0].name, "a.png");
  EXPECT_TRUE(images[0].points2d.empty());
  EXPECT_EQ(images[1].name, "b.png");
  ASSERT_EQ(images[1].points2d.size(), 2u);
  EXPECT_EQ(images[1].point3d_ids, (std::vector<long long>{7, -1}));
  EXPECT_EQ(images[2].name, "c.png");
  // QW QX QY QZ = 0.5 0.5 0.5 0.5 is unit; TX TY TZ kept.
  EXPECT_EQ(images[2].cam_from_world.translation, Eigen::Vector3d(1, 2, 3));
}

TEST(ColmapTextTest, CrlfLinesAreRead) {
  const std::string dir = testing::MakeTempDir("colmap");
  testing::WriteText(dir + "/images.txt", std::string("# x\r\n1 ") + kPose + " 1 a.png\r\n\r\n2 " +
                                              kPose + " 1 b.png\r\n\r\n");
  std::vector<PosedImage> images;
  ASSERT_TRUE(ReadColmapImages(dir + "/images.txt", &images).ok());
  ASSERT_EQ(images.size(), 2u);
  EXPECT_EQ(images[1].name, "b.png");
}

TEST(ColmapTextTest, NonUnitQuaternionIsNormalized) {
  const std::string dir = testing::MakeTempDir("colmap");
  testing::WriteText(dir + "/images.txt", "1 2 0 0 0 1 2 3 1 a.png\n\n");
  std::vector<PosedImage> images;
  ASSERT_TRUE(ReadColmapImages(dir + "/images.txt", &images).ok());
  EXPECT_DOUBLE_EQ(images[0].cam_from_world.rotation.norm(), 1.0);
  EXPECT_DOUBLE_EQ(images[0].cam_from_world.rotation.w(), 1.0);
}

TEST(ColmapTextTest, ImageErrorsNameLineAndField) {
  const std::string header = "# Image list\n# two lines per image\n";
  const std::string good = std::string("1 ") + kPose + " 1 a.png\n\n";
  EXPECT_EQ(ReadImagesError(header + good + "2 x 0 0 0 1 2 3 1 b.png\n\n"),
            "images.txt:5: QW: not a number ('x')");
  EXPECT_EQ(ReadImagesError(header + good + "2 1 0 0 0 1 nan 3 1 b.png\n\n"),
            "images.txt:5: TY: not finite (nan)");
  EXPECT_EQ(ReadImagesError(header + good + "2 1 0 0 0 inf 2 3 1 b.png\n\n"),
            "images.txt:5: TX: not finite (inf)");
  EXPECT_EQ(ReadImagesError(header + good + "2 0 0 0 0 1 2 3 1 b.png\n\n"),
            "images.txt:5: quaternion: zero norm, not a rotation");
  EXPECT_EQ(ReadImagesError(header + good + "1 " + kPose + " 1 b.png\n\n"),
            "images.txt:5: IMAGE_ID: duplicate id 1 (first at line 3)");
  EXPECT_EQ(ReadImagesError(header + good + "2 " + kPose + " 1 a.png\n\n"),
            "images.txt:5: NAME: duplicate name 'a.png' (first at line 3)");
  EXPECT_THAT(ReadImagesError(header + "1 " + kPose + " 1\n\n"),
              StartsWith("images.txt:3: expected 'IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME'"));
  EXPECT_EQ(ReadImagesError(header + "1.5 " + kPose + " 1 a.png\n\n"),
            "images.txt:3: IMAGE_ID: not an integer ('1.5')");
  EXPECT_EQ(ReadImagesError(header + "1 " + kPose + " one a.png\n\n"),
            "images.txt:3: CAMERA_ID: not an integer ('one')");
  EXPECT_THAT(ReadImagesError(header + good + "2 " + kPose + " 1 b.png\n1 2\n"),
              StartsWith("images.txt:6: POINTS2D: expected (X, Y, POINT3D_ID) triples"));
  EXPECT_EQ(ReadImagesError(header + good + "2 " + kPose + " 1 b.png\n1 2 3 4 y 5\n"),
            "images.txt:6: POINTS2D[1].Y: not a number ('y')");
}

TEST(ColmapTextTest, CameraErrorsNameLineAndField) {
  EXPECT_THAT(ReadCamerasError("# c\n1 FISHEYE 640 480 1 2 3\n"),
              StartsWith("cameras.txt:2: MODEL: unsupported camera model 'FISHEYE'"));
  EXPECT_EQ(ReadCamerasError("1 PINHOLE 640 480 500 500 320\n"),
            "cameras.txt:1: PARAMS: PINHOLE takes 4 parameters, got 3");
  EXPECT_EQ(ReadCamerasError("1 PINHOLE 640 480 500 nan 320 240\n"),
            "cameras.txt:1: PARAMS[1]: not finite (nan)");
  EXPECT_EQ(ReadCamerasError("1 PINHOLE 0 480 500 500 320 240\n"),
            "cameras.txt:1: WIDTH: must be positive");
  EXPECT_EQ(ReadCamerasError("1 PINHOLE 640 480 500 500 320 240\n1 PINHOLE 640 480 500 500 320 "
                             "240\n"),
            "cameras.txt:2: CAMERA_ID: duplicate id 1 (first at line 1)");
  EXPECT_THAT(ReadCamerasError("1 PINHOLE 640 480 -500 500 320 240\n"),
              StartsWith("cameras.txt:1: camera 1"));
}

TEST(ColmapTextTest, PointErrorsNameLineAndField) {
  const std::string path = testing::MakeTempDir("colmap") + "/points3D.txt";
  testing::WriteText(path, "# p\n1 0 0 0 1 2 3 0.5 1 0\n2 0 0 0 1 2 300 0.5\n");
  std::vector<Point3D> points;
  Status status = ReadColmapPoints(path, &points);
  EXPECT_EQ(status.message(), path + ":3: B: outside 0..255 (300)");
  testing::WriteText(path, "1 0 0 0 1 2 3 0.5 1\n");
  status = ReadColmapPoints(path, &points);
  EXPECT_THAT(status.message(), StartsWith(path + ":1: expected 'POINT3D_ID X Y Z R G B ERROR'"));
}

TEST(ColmapTextTest, MissingFilesAreNamed) {
  const std::string dir = testing::MakeTempDir("colmap");
  std::vector<PosedImage> images;
  Status status = ReadColmapImages(dir + "/nope/images.txt", &images);
  EXPECT_EQ(status.message(), dir + "/nope/images.txt: no such file");
  ColmapModel model;
  status = ReadColmapModel(dir, &model);
  EXPECT_EQ(status.message(), dir + "/cameras.txt: no such file");
  bool is_tum = true;
  status = ReadPoses(dir, &images, &is_tum);
  EXPECT_THAT(status.message(), StartsWith(dir + ": folder holds no images.txt"));
}

TEST(ColmapTextTest, ModelImagesMustUseKnownCameras) {
  const std::string dir = testing::MakeTempDir("colmap");
  testing::WriteText(dir + "/cameras.txt", "1 PINHOLE 640 480 500 500 320 240\n");
  testing::WriteText(dir + "/images.txt", std::string("1 ") + kPose + " 3 a.png\n\n");
  ColmapModel model;
  const Status status = ReadColmapModel(dir, &model);
  EXPECT_EQ(status.message(),
            dir + "/images.txt: image 'a.png' (IMAGE_ID 1): CAMERA_ID 3 is not in " + dir +
                "/cameras.txt");
}

TEST(ColmapTextTest, ReadPosesTakesAFolderOrImagesTxt) {
  const std::string dir = testing::MakeTempDir("colmap");
  ColmapModel model;
  model.cameras = EveryColmapModel();
  model.images = {MakeImage(1, 1, "a.png", 2), MakeImage(2, 2, "b.png", 0)};
  ASSERT_TRUE(WriteColmapModel(dir, model).ok());
  for (const std::string& path : {dir, dir + "/images.txt"}) {
    std::vector<PosedImage> poses;
    bool is_tum = true;
    const Status status = ReadPoses(path, &poses, &is_tum);
    ASSERT_TRUE(status.ok()) << status.message();
    EXPECT_FALSE(is_tum);
    ASSERT_EQ(poses.size(), 2u);
    ExpectSameImage(poses[1], model.images[1]);
  }
}

TEST(ColmapTextTest, ReadsARealColmapExport) {
  FRESCO_REQUIRE_SHARED_DATA();
  const std::string dir = testing::SharedDataDir() + "/sceaux-castle-openmvs/colmap_sparse_txt";
  ColmapModel model;
  const Status status = ReadColmapModel(dir, &model);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(model.cameras.size(), 1u);
  const Camera& camera = model.cameras.at(1);
  EXPECT_EQ(camera.model, LensModel::kColmapPinhole);
  EXPECT_EQ(camera.width, 1416);
  EXPECT_EQ(camera.height, 1064);
  EXPECT_DOUBLE_EQ(camera.fx, 1492.6641714577);
  EXPECT_DOUBLE_EQ(camera.cx, 726.3179316289 - 0.5);
  EXPECT_DOUBLE_EQ(camera.cy, 562.7669694372 - 0.5);
  ASSERT_EQ(model.images.size(), 10u);
  for (int i = 0; i < 10; ++i) {
    const PosedImage& image = model.images[i];
    EXPECT_EQ(image.image_id, i + 1);
    EXPECT_EQ(image.camera_id, 1);
    char name[16];
    std::snprintf(name, sizeof(name), "%05d.jpg", i);
    EXPECT_EQ(image.name, name);
    EXPECT_TRUE(image.points2d.empty());
    EXPECT_NEAR(image.cam_from_world.rotation.norm(), 1.0, 1e-15);
  }
  EXPECT_NEAR(model.images[0].cam_from_world.rotation.w(), 0.622321055679, 1e-11);
  EXPECT_DOUBLE_EQ(model.images[0].cam_from_world.translation.z(), 8.217525787674);
  EXPECT_TRUE(model.points.empty());
  // Every photo the poses list is in images/ and the cameras sit ~8-9 m from the facade.
  for (const PosedImage& image : model.images) {
    EXPECT_TRUE(std::filesystem::exists(dir + "/../images/" + image.name)) << image.name;
    EXPECT_GT(image.cam_from_world.Centre().norm(), 1.0);
  }
}

}  // namespace
}  // namespace fresco
