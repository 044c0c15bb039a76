// LoadCapture: a project's files loaded and matched (frames to poses by name or order, poses
// to cameras), and every mismatch reported with the file and what is wrong.
#include "pipeline/core/capture.h"

#include <filesystem>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "tests/test_support.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::StartsWith;

// One triangle, its buffer embedded as a data URI (3 float vec3 positions).
const char kTriangleGltf[] = R"({
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
  "buffers": [{"byteLength": 36,
    "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],
  "bufferViews": [{"buffer": 0, "byteLength": 36}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                 "min": [0, 0, 0], "max": [1, 1, 0]}]
})";

const char kPose[] = "1 0 0 0 0 0 5";

// A capture folder: frames/ (3 PNGs), sparse/cameras.txt + images.txt, project.json.
class CaptureTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTempDir("capture");
    fs::create_directories(dir_ + "/frames");
    for (int i = 0; i < 3; ++i) {
      const cv::Mat image(24, 32, CV_8UC3, cv::Scalar(i, 2 * i, 3 * i));
      ASSERT_TRUE(cv::imwrite(dir_ + "/frames/" + Name(i), image));
    }
    testing::WriteText(dir_ + "/sparse/cameras.txt",
                       "1 PINHOLE 32 24 30 30 16 12\n2 SIMPLE_PINHOLE 32 24 28 16 12\n");
    WriteImages(
        {"1 " + std::string(kPose) + " 1 000000.png", "2 " + std::string(kPose) + " 2 000002.png"});
    testing::WriteText(dir_ + "/scene.gltf", kTriangleGltf);
    project_.file_path = dir_ + "/project.json";
    project_.scene = "scene.gltf";
    project_.camera = "sparse/cameras.txt";
    project_.video = "frames/";
    project_.poses = "sparse/images.txt";
    options_.load_scene = false;
  }

  static std::string Name(int i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", i);
    return name;
  }

  void WriteImages(const std::vector<std::string>& lines) {
    std::string text = "# IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME\n";
    for (const std::string& line : lines) text += line + "\n\n";
    testing::WriteText(dir_ + "/sparse/images.txt", text);
  }

  Status Load(Capture* capture) { return LoadCapture(project_, options_, capture); }

  std::string LoadError() {
    Capture capture;
    const Status status = Load(&capture);
    EXPECT_FALSE(status.ok());
    return status.message();
  }

  std::string dir_;
  Project project_;
  CaptureLoadOptions options_;
};

TEST_F(CaptureTest, MatchesFramesToColmapPosesByName) {
  Capture capture;
  const Status status = Load(&capture);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_FALSE(capture.poses_are_tum);
  ASSERT_EQ(capture.cameras.size(), 2u);
  ASSERT_EQ(capture.poses.size(), 2u);
  ASSERT_TRUE(capture.video);
  EXPECT_EQ(capture.video->FrameCount(), 3);

  Frame frame;
  Status read;
  std::vector<const PosedImage*> matched;
  while (capture.video->Next(&frame, &read)) matched.push_back(capture.PoseForFrame(frame));
  ASSERT_EQ(matched.size(), 3u);
  ASSERT_NE(matched[0], nullptr);
  EXPECT_EQ(matched[0]->image_id, 1);
  EXPECT_EQ(matched[1], nullptr);  // 000001.png has no pose
  ASSERT_NE(matched[2], nullptr);
  EXPECT_EQ(matched[2]->image_id, 2);
  // Each pose uses its own CAMERA_ID.
  EXPECT_EQ(capture.CameraFor(*matched[0])->model, LensModel::kColmapPinhole);
  EXPECT_EQ(capture.CameraFor(*matched[2])->model, LensModel::kSimplePinhole);
  EXPECT_DOUBLE_EQ(capture.CameraFor(*matched[0])->cx, 15.5);
}

TEST_F(CaptureTest, MatchesByStemWhenTheExtensionDiffers) {
  WriteImages({"1 " + std::string(kPose) + " 1 000001.jpg",
               "2 " + std::string(kPose) + " 1 images/000002.png"});
  Capture capture;
  const Status status = Load(&capture);
  ASSERT_TRUE(status.ok()) << status.message();
  Frame frame;
  frame.index = 1;
  frame.name = "000001.png";
  ASSERT_NE(capture.PoseForFrame(frame), nullptr);
  EXPECT_EQ(capture.PoseForFrame(frame)->image_id, 1);
  frame.name = "000002.png";
  ASSERT_NE(capture.PoseForFrame(frame), nullptr);
  EXPECT_EQ(capture.PoseForFrame(frame)->image_id, 2);
  frame.name = "000000.png";
  EXPECT_EQ(capture.PoseForFrame(frame), nullptr);
}

TEST_F(CaptureTest, ImageListedButMissingFromTheFolder) {
  WriteImages(
      {"1 " + std::string(kPose) + " 1 000000.png", "2 " + std::string(kPose) + " 1 x.png"});
  EXPECT_EQ(LoadError(),
            "sparse/images.txt: image 'x.png' is listed but missing from video folder frames/");
}

TEST_F(CaptureTest, PoseWithAnUnknownCamera) {
  WriteImages({"1 " + std::string(kPose) + " 9 000000.png"});
  EXPECT_EQ(LoadError(),
            "sparse/images.txt: image '000000.png' (IMAGE_ID 1): CAMERA_ID 9 is "
            "not in sparse/cameras.txt");
}

TEST_F(CaptureTest, NanInAPoseNamesTheLine) {
  WriteImages({"1 " + std::string(kPose) + " 1 000000.png", "2 1 0 0 0 nan 0 5 1 000001.png"});
  EXPECT_EQ(LoadError(), dir_ + "/sparse/images.txt:4: TX: not finite (nan)");
}

TEST_F(CaptureTest, MissingFilesNameTheProjectTheKeyAndThePath) {
  project_.camera = "sparse/nope.txt";
  EXPECT_EQ(LoadError(), dir_ + "/project.json: camera: 'sparse/nope.txt' does not exist (" + dir_ +
                             "/sparse/nope.txt)");
  project_.camera = "sparse/cameras.txt";
  project_.video = "missing_frames/";
  EXPECT_THAT(LoadError(), StartsWith(dir_ + "/project.json: video: 'missing_frames/' does not "
                                             "exist"));
  project_.video = "frames/";
  project_.poses = "poses.tum";
  EXPECT_THAT(LoadError(), StartsWith(dir_ + "/project.json: poses: 'poses.tum'"));
  project_.poses = "sparse/images.txt";
  project_.truth.poses = "truth.txt";
  EXPECT_THAT(LoadError(), StartsWith(dir_ + "/project.json: truth.poses: 'truth.txt'"));
  project_.truth.poses = "";
  options_.load_scene = true;
  project_.scene = "gone.gltf";
  EXPECT_THAT(LoadError(), StartsWith(dir_ + "/project.json: scene: 'gone.gltf'"));
}

TEST_F(CaptureTest, TumPosesMatchFramesInOrder) {
  testing::WriteText(dir_ + "/poses.tum",
                     "# t x y z qx qy qz qw\n0 0 0 -5 0 0 0 1\n"
                     "0.033 0.1 0 -5 0 0 0 1\n");
  testing::WriteText(dir_ + "/camera.txt", "3 PINHOLE 32 24 30 30 16 12\n");
  project_.poses = "poses.tum";
  project_.camera = "camera.txt";
  project_.truth.poses = "poses.tum";
  Capture capture;
  const Status status = Load(&capture);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_TRUE(capture.poses_are_tum);
  EXPECT_EQ(capture.truth_poses.size(), 2u);
  Frame frame;
  Status read;
  ASSERT_TRUE(capture.video->Next(&frame, &read));
  const PosedImage* pose = capture.PoseForFrame(frame);
  ASSERT_NE(pose, nullptr);
  EXPECT_TRUE(pose->cam_from_world.Centre().isApprox(Eigen::Vector3d(0, 0, -5)));
  ASSERT_NE(capture.CameraFor(*pose), nullptr);  // the only camera, whatever its id
  EXPECT_EQ(capture.CameraFor(*pose)->width, 32);
  ASSERT_TRUE(capture.video->Next(&frame, &read));
  ASSERT_NE(capture.PoseForFrame(frame), nullptr);
  EXPECT_DOUBLE_EQ(capture.PoseForFrame(frame)->cam_from_world.Centre().x(), 0.1);
  ASSERT_TRUE(capture.video->Next(&frame, &read));
  EXPECT_EQ(capture.PoseForFrame(frame), nullptr);  // 3 frames, 2 poses
}

TEST_F(CaptureTest, TumPosesNeedASingleCamera) {
  testing::WriteText(dir_ + "/poses.tum", "0 0 0 -5 0 0 0 1\n");
  project_.poses = "poses.tum";
  EXPECT_THAT(LoadError(), StartsWith("poses.tum: TUM poses name no camera, but "
                                      "sparse/cameras.txt holds 2 cameras"));
}

TEST_F(CaptureTest, EmptyPosesFileIsAnError) {
  WriteImages({});
  EXPECT_EQ(LoadError(), "sparse/images.txt: holds no poses");
}

TEST_F(CaptureTest, ProjectFileRoundTripToCapture) {
  // Through the project file, with the scene.
  testing::WriteText(dir_ + "/project.json", R"({"fresco": 1, "scene": "scene.gltf",
    "camera": "sparse/cameras.txt", "video": "frames/", "poses": "sparse/"})");
  Project project;
  ASSERT_TRUE(LoadProject(dir_ + "/project.json", {}, &project).ok());
  Capture capture;
  const Status status = LoadCapture(project, CaptureLoadOptions(), &capture);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(capture.scene.mesh.NumTriangles(), 1);
  EXPECT_EQ(capture.poses.size(), 2u);
}

TEST_F(CaptureTest, WithoutVideo) {
  options_.open_video = false;
  Capture capture;
  ASSERT_TRUE(Load(&capture).ok());
  EXPECT_FALSE(capture.video);
  Frame frame;
  frame.name = "000002.png";
  ASSERT_NE(capture.PoseForFrame(frame), nullptr);
  EXPECT_EQ(capture.PoseForFrame(frame)->image_id, 2);
}

TEST(CaptureRealDataTest, SceauxCastleColmapExport) {
  FRESCO_REQUIRE_SHARED_DATA();
  const std::string data = testing::SharedDataDir() + "/sceaux-castle-openmvs";
  Project project;
  project.file_path = testing::MakeTempDir("capture") + "/project.json";
  project.camera = data + "/colmap_sparse_txt/cameras.txt";
  project.poses = data + "/colmap_sparse_txt";
  project.video = data + "/images";
  CaptureLoadOptions options;
  options.load_scene = false;
  Capture capture;
  const Status status = LoadCapture(project, options, &capture);
  ASSERT_TRUE(status.ok()) << status.message();
  Frame frame;
  Status read;
  int matched = 0;
  while (capture.video->Next(&frame, &read)) {
    const PosedImage* pose = capture.PoseForFrame(frame);
    ASSERT_NE(pose, nullptr) << frame.name;
    EXPECT_EQ(pose->name, frame.name);
    EXPECT_EQ(capture.CameraFor(*pose)->width, frame.bgr.cols);
    ++matched;
    if (matched == 2) break;  // decoding all ten 1416x1064 photos is slow; two suffice
  }
  EXPECT_EQ(matched, 2);
}

}  // namespace
}  // namespace fresco
