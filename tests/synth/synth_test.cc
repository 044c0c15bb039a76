// Synthetic captures against what they promise: deterministic for a seed; the true poses
// put known scene points on the rendered pixels of their texture (pinhole and distorted
// lenses); pose noise and exposure gains with the requested statistics; movers in the frames
// but never in the written scene; a written folder that LoadProject + LoadCapture accept
// with a pose for every frame; and `fresco synth` on the command line, bad input included.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <new>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/capture.h"
#include "pipeline/core/project.h"
#include "pipeline/core/scene.h"
#include "pipeline/render/renderer.h"
#include "pipeline/synth/blocks_scene.h"
#include "pipeline/synth/camera_path.h"
#include "pipeline/synth/movers.h"
#include "pipeline/synth/procedural_scenes.h"
#include "pipeline/synth/synth_spec.h"
#include "pipeline/synth/synth_writer.h"
#include "pipeline/synth/synthesize.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using testing::MakeTempDir;
using testing::RunFresco;

// FRESCO_SOURCE_DIR and FRESCO_BINARY as CMake knows them, where CTest did not set them.
class SynthTestEnvironment : public ::testing::Environment {
 public:
  void SetUp() override {
#ifdef FRESCO_TEST_SOURCE_DIR
    setenv("FRESCO_SOURCE_DIR", FRESCO_TEST_SOURCE_DIR, /*overwrite=*/0);
#endif
#ifdef FRESCO_TEST_BINARY
    setenv("FRESCO_BINARY", FRESCO_TEST_BINARY, /*overwrite=*/0);
#endif
  }
};
const ::testing::Environment* const kEnvironment =
    ::testing::AddGlobalTestEnvironment(new SynthTestEnvironment);

Scene Room(unsigned seed = 1) {
  CubeRoomOptions room;
  room.procedural_texture_px = 256;
  room.seed = seed;
  Scene scene;
  EXPECT_TRUE(MakeCubeRoomScene(room, &scene).ok());
  return scene;
}

// A small capture inside the room: hand-held, looking freely around.
SynthOptions RoomOptions(int frames, int width = 96, int height = 72) {
  SynthOptions o;
  o.frames = frames;
  o.width = width;
  o.height = height;
  o.path = CameraPathKind::kHandheld;
  o.target = Eigen::Vector3d(0, 1.5, 0);
  o.height_m = 1.5;
  o.radius_m = 0.4;
  o.wander_m = 0.2;
  o.look_at_target = false;
  o.pitch_deg = -5;
  return o;
}

TEST(SynthCamera, HfovGivesFocalLengthAndLensesAreMild) {
  Camera c;
  ASSERT_TRUE(MakeSynthCamera(LensModel::kPinhole, 640, 480, 90.0, &c).ok());
  EXPECT_NEAR(c.fx, 320.0, 1e-9);
  EXPECT_NEAR(c.cx, 319.5, 1e-12);
  EXPECT_NEAR(c.cy, 239.5, 1e-12);
  for (LensModel lens : {LensModel::kOpenCV4, LensModel::kOpenCV5, LensModel::kOpenCV8}) {
    ASSERT_TRUE(MakeSynthCamera(lens, 640, 480, 70.0, &c).ok());
    EXPECT_TRUE(c.HasDistortion());
    EXPECT_TRUE(c.Validate("synth").ok());
    // The corner moves by a few percent of the image, and unprojects back.
    Eigen::Vector2d n, corner(0, 0);
    ASSERT_TRUE(c.Unproject(corner, &n));
    const Eigen::Vector2d pinhole = c.PixelFromNormalized(n);  // distorted again
    EXPECT_NEAR((pinhole - corner).norm(), 0.0, 1e-6);
    const Eigen::Vector2d undistorted(c.fx * n.x() + c.cx, c.fy * n.y() + c.cy);
    const double shift = (undistorted - corner).norm();
    EXPECT_GT(shift, 2.0);
    EXPECT_LT(shift, 0.08 * 640);
  }
  EXPECT_FALSE(MakeSynthCamera(LensModel::kPinhole, 0, 480, 70.0, &c).ok());
  EXPECT_FALSE(MakeSynthCamera(LensModel::kPinhole, 640, 480, 179.0, &c).ok());
}

TEST(CameraPath, LookAtPutsTheTargetInTheCentreUpright) {
  const Eigen::Vector3d eye(1, 2, 3), target(-1, 1.5, 0.5);
  const Rigid3d pose = LookAt(eye, target);
  EXPECT_NEAR((pose * eye).norm(), 0.0, 1e-12);
  const Eigen::Vector3d t = pose * target;
  EXPECT_NEAR(t.x(), 0.0, 1e-12);
  EXPECT_NEAR(t.y(), 0.0, 1e-12);
  EXPECT_GT(t.z(), 0.0);
  // World up is image up (camera -y), world +Y above the target projects higher.
  EXPECT_LT((pose * (target + Eigen::Vector3d(0, 0.1, 0))).y(), 0.0);
}

TEST(CameraPath, PathsAreSmoothDeterministicAndSeeded) {
  for (CameraPathKind kind :
       {CameraPathKind::kOrbit, CameraPathKind::kWalk, CameraPathKind::kHandheld}) {
    CameraPathOptions o;
    o.kind = kind;
    o.radius_m = 2.0;
    const auto a = MakeCameraPath(o, 120, 7), b = MakeCameraPath(o, 120, 7);
    ASSERT_EQ(a.size(), 120u);
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].rotation.coeffs(), b[i].rotation.coeffs());
      EXPECT_EQ(a[i].translation, b[i].translation);
    }
    for (size_t i = 1; i < a.size(); ++i) {  // smooth: small steps between frames
      EXPECT_LT((a[i].Centre() - a[i - 1].Centre()).norm(), 0.2) << CameraPathKindName(kind);
      EXPECT_LT(RotationDifferenceDeg(a[i].rotation, a[i - 1].rotation), 8.0);
    }
  }
  CameraPathOptions o;
  const auto a = MakeCameraPath(o, 30, 1), c = MakeCameraPath(o, 30, 2);
  EXPECT_GT((a[10].Centre() - c[10].Centre()).norm(), 1e-3);
}

TEST(ProceduralScenes, FacesPointWhereTheyAreSeenFrom) {
  const Scene room = Room();
  ASSERT_EQ(room.mesh.NumTriangles(), 12);
  ASSERT_EQ(room.textures.size(), 6u);
  const Eigen::Vector3d inside(0, 1.5, 0);
  for (int t = 0; t < room.mesh.NumTriangles(); ++t) {
    const Eigen::Vector3d centroid =
        (room.mesh.Corner(t, 0) + room.mesh.Corner(t, 1) + room.mesh.Corner(t, 2)) / 3.0;
    EXPECT_GT(room.mesh.Normal(t).dot(inside - centroid), 0.0) << "room triangle " << t;
  }
  // Wall images read upright and unmirrored from inside: u grows to the viewer's right, v
  // grows downwards.
  for (int t = 0; t < room.mesh.NumTriangles(); ++t) {
    const Eigen::Vector3d n = room.mesh.Normal(t);
    if (std::abs(n.y()) > 0.5) continue;
    const Eigen::Vector3d right = (-n).cross(Eigen::Vector3d::UnitY());
    double u_right = 0, v_up = 0;
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3;
      const Eigen::Vector3d d = room.mesh.Corner(t, j) - room.mesh.Corner(t, i);
      const Eigen::Vector2f duv = room.mesh.uvs[t][j] - room.mesh.uvs[t][i];
      u_right += duv.x() * d.dot(right);
      v_up += duv.y() * d.y();
    }
    EXPECT_GT(u_right, 0.0) << "room triangle " << t;
    EXPECT_LT(v_up, 0.0) << "room triangle " << t;
  }
  const Scene cube = MakeTexturedCubeScene(1.0);
  ASSERT_EQ(cube.mesh.NumTriangles(), 12);
  for (int t = 0; t < cube.mesh.NumTriangles(); ++t) {
    const Eigen::Vector3d centroid =
        (cube.mesh.Corner(t, 0) + cube.mesh.Corner(t, 1) + cube.mesh.Corner(t, 2)) / 3.0;
    EXPECT_GT(cube.mesh.Normal(t).dot(centroid), 0.0) << "cube triangle " << t;
  }
  const Scene plane = MakeTexturedPlaneScene(2, 1);
  EXPECT_NEAR(plane.mesh.Normal(0).z(), 1.0, 1e-12);
  Scene street;
  ASSERT_TRUE(MakeStreetScene(StreetOptions(), &street).ok());
  EXPECT_GT(street.mesh.NumTriangles(), 40);
  // Procedural textures are deterministic and have corners.
  const cv::Mat f1 = MakeFeatureTexture(256, 256, 3), f2 = MakeFeatureTexture(256, 256, 3);
  EXPECT_EQ(cv::norm(f1, f2, cv::NORM_INF), 0.0);
  cv::Mat gray;
  cv::cvtColor(f1, gray, cv::COLOR_RGBA2GRAY);
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(gray, corners, 200, 0.01, 4, cv::noArray(), 3, /*harris=*/true);
  EXPECT_GT(corners.size(), 30u);
}

TEST(ProceduralScenes, BlocksStandApartEveryFaceItsOwnTexture) {
  BlocksOptions options;
  Scene a, b, other;
  ASSERT_TRUE(MakeBlocksScene(options, &a).ok());
  ASSERT_TRUE(MakeBlocksScene(options, &b).ok());
  options.seed = 2;
  ASSERT_TRUE(MakeBlocksScene(options, &other).ok());
  // Ground + 7 boxes x 5 faces, two triangles each, one texture per face.
  ASSERT_EQ(a.mesh.NumTriangles(), 2 * (1 + 5 * 7));
  EXPECT_EQ(a.textures.size(), 1u + 5 * 7);
  EXPECT_EQ(a.mesh.vertices, b.mesh.vertices);  // deterministic
  EXPECT_NE(a.mesh.vertices, other.mesh.vertices);
  for (size_t i = 1; i < a.textures.size(); ++i) {  // nothing repeats
    const cv::Mat& t = a.textures[i].rgba;
    const cv::Mat& u = a.textures[i - 1].rgba;
    if (t.size() == u.size()) {
      EXPECT_GT(cv::norm(t, u, cv::NORM_L1), 0.0) << i;
    }
  }
  // Box footprints (the bottom corners of each box's first side and of its top) do not
  // overlap, and everything stands on y = 0 within the area.
  Eigen::Vector3d lo, hi;
  a.Bounds(&lo, &hi);
  EXPECT_NEAR(lo.y(), 0.0, 1e-12);
  EXPECT_LE(hi.y(), options.max_height_m + 1e-9);
  EXPECT_NEAR(hi.x() - lo.x(), options.ground_m, 1e-9);
  // Every box face points away from its box: normals of the faces of box k point away from
  // the box's centre.
  for (int box = 0; box < 7; ++box) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    const int first = 2 * (1 + 5 * box);
    for (int t = first; t < first + 10; ++t) centre += a.mesh.Corner(t, 0) / 10.0;
    for (int t = first; t < first + 10; ++t) {
      EXPECT_GT(a.mesh.Normal(t).dot(a.mesh.Corner(t, 1) - centre), 0.0) << box << " " << t;
    }
  }
}

TEST(Synthesize, SameSeedSameFramesOtherSeedOtherFrames) {
  const Scene scene = Room();
  SynthOptions o = RoomOptions(4);
  o.random_movers = 1;
  o.exposure_jitter = 0.1;
  o.pose_noise_deg = 0.5;
  SynthCapture a, b, c;
  ASSERT_TRUE(SynthesizeCapture(scene, o, &a).ok());
  o.threads = 1;  // thread count must not matter
  ASSERT_TRUE(SynthesizeCapture(scene, o, &b).ok());
  o.seed = 2;
  ASSERT_TRUE(SynthesizeCapture(scene, o, &c).ok());
  ASSERT_EQ(a.frames_bgr.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    ASSERT_EQ(a.frames_bgr[i].size(), cv::Size(96, 72));
    ASSERT_EQ(a.frames_bgr[i].type(), CV_8UC3);
    EXPECT_EQ(cv::norm(a.frames_bgr[i], b.frames_bgr[i], cv::NORM_INF), 0.0) << i;
    EXPECT_EQ(a.given_poses[i].cam_from_world.translation,
              b.given_poses[i].cam_from_world.translation);
    EXPECT_EQ(a.true_poses[i].name, SynthFrameName(i));
  }
  EXPECT_GT(cv::norm(a.frames_bgr[2], c.frames_bgr[2], cv::NORM_L1), 0.0);
}

// Renders a plane with a checker and checks, at points well inside the squares, that the
// pixel where the true pose projects the point has the square's colour.
void CheckCheckerProjection(LensModel lens) {
  const int squares = 8;
  const cv::Vec4b light(230, 200, 40, 255), dark(20, 60, 160, 255);
  const Scene scene =
      MakeTexturedPlaneScene(2.0, 2.0, MakeCheckerTexture(512, 512, squares, squares, light, dark));
  SynthOptions o;
  o.frames = 3;
  o.width = 320;
  o.height = 240;
  o.lens = lens;
  o.hfov_deg = 60;
  o.path = CameraPathKind::kHandheld;
  o.target = Eigen::Vector3d::Zero();
  o.radius_m = 2.2;
  o.height_m = 0.3;
  o.start_deg = 80;
  o.turns = 0.05;
  o.wander_m = 0.2;
  o.wobble_deg = 2;
  SynthCapture capture;
  ASSERT_TRUE(SynthesizeCapture(scene, o, &capture).ok());
  int checked = 0;
  for (size_t f = 0; f < capture.frames_bgr.size(); ++f) {
    const Rigid3d& pose = capture.true_poses[f].cam_from_world;
    for (int sy = 0; sy < squares; ++sy) {
      for (int sx = 0; sx < squares; ++sx) {
        for (double du : {0.3, 0.5, 0.7}) {
          // Point in square (sx, sy): u right, v down from the top-left (-1, +1).
          const double u = (sx + du) / squares, v = (sy + 1.0 - du) / squares;
          const Eigen::Vector3d point(-1.0 + 2.0 * u, 1.0 - 2.0 * v, 0.0);
          Eigen::Vector2d pixel;
          if (!capture.camera.Project(pose * point, &pixel)) continue;
          const int x = static_cast<int>(std::lround(pixel.x())),
                    y = static_cast<int>(std::lround(pixel.y()));
          if (x < 1 || y < 1 || x > o.width - 2 || y > o.height - 2) continue;
          const cv::Vec4b expected = (sx + sy) % 2 == 0 ? light : dark;
          const cv::Vec3b got = capture.frames_bgr[f].at<cv::Vec3b>(y, x);
          for (int ch = 0; ch < 3; ++ch) {
            EXPECT_NEAR(got[2 - ch], expected[ch], 12)
                << "frame " << f << " square " << sx << "," << sy;
          }
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(checked, 300);
}

TEST(Synthesize, TruePosesProjectScenePointsOntoTheirTexturePinhole) {
  CheckCheckerProjection(LensModel::kPinhole);
}

TEST(Synthesize, TruePosesProjectScenePointsOntoTheirTextureDistorted) {
  CheckCheckerProjection(LensModel::kOpenCV5);
}

TEST(Synthesize, PoseNoiseHasTheRequestedRms) {
  const Scene scene = Room();
  SynthOptions o = RoomOptions(2000);
  o.pose_noise_deg = 0.5;
  o.pose_noise_m = 0.04;
  SynthCapture plan;  // planning renders nothing
  ASSERT_TRUE(PlanSynthCapture(scene, o, &plan).ok());
  double sum_deg2 = 0, sum_m2 = 0;
  for (size_t i = 0; i < plan.true_poses.size(); ++i) {
    const Rigid3d& t = plan.true_poses[i].cam_from_world;
    const Rigid3d& g = plan.given_poses[i].cam_from_world;
    sum_deg2 += std::pow(RotationDifferenceDeg(t.rotation, g.rotation), 2);
    sum_m2 += (t.Centre() - g.Centre()).squaredNorm();
    EXPECT_EQ(plan.true_poses[i].name, plan.given_poses[i].name);
  }
  const double n = static_cast<double>(plan.true_poses.size());
  EXPECT_NEAR(std::sqrt(sum_deg2 / n), 0.5, 0.05);
  EXPECT_NEAR(std::sqrt(sum_m2 / n), 0.04, 0.004);
  // Without noise the given poses are the true ones.
  o.pose_noise_deg = o.pose_noise_m = 0;
  ASSERT_TRUE(PlanSynthCapture(scene, o, &plan).ok());
  for (size_t i = 0; i < plan.true_poses.size(); ++i) {
    EXPECT_EQ(plan.true_poses[i].cam_from_world.translation,
              plan.given_poses[i].cam_from_world.translation);
  }
}

// Out of memory while frames are rendered on several threads comes back to the caller as
// the exception (the CLI turns it into a one-line error), never ends the process.
TEST(Synthesize, AnExceptionWhileRenderingOnThreadsReachesTheCaller) {
  const Scene scene = Room();
  SynthOptions o = RoomOptions(12);
  o.threads = 2;
  SynthCapture plan;
  ASSERT_TRUE(PlanSynthCapture(scene, o, &plan).ok());
  int emitted = 0;
  EXPECT_THROW(RenderSynthFrames(scene, o, plan,
                                 [&](int i, const cv::Mat&) {
                                   if (i == 3) throw std::bad_alloc();
                                   ++emitted;
                                   return Status::Ok();
                                 }),
               std::bad_alloc);
  EXPECT_EQ(emitted, 3);
  // The same capture renders whole afterwards: nothing was left locked or running.
  emitted = 0;
  EXPECT_TRUE(RenderSynthFrames(scene, o, plan, [&](int, const cv::Mat&) {
                ++emitted;
                return Status::Ok();
              }).ok());
  EXPECT_EQ(emitted, 12);
}

TEST(Synthesize, ExposureGainsScaleTheFrames) {
  const Scene scene = Room();
  SynthOptions o = RoomOptions(2000);
  o.exposure_jitter = 0.1;
  SynthCapture plan;
  ASSERT_TRUE(PlanSynthCapture(scene, o, &plan).ok());
  double sum = 0, sum2 = 0;
  for (double g : plan.exposure_gains) {
    sum += std::log(g);
    sum2 += std::log(g) * std::log(g);
  }
  const double n = static_cast<double>(plan.exposure_gains.size());
  EXPECT_NEAR(std::sqrt(sum2 / n), 0.1, 0.03);
  EXPECT_NEAR(sum / n, 0.0, 0.04);
  // A frame with gain g is the frame without exposure changes times g.
  o.frames = 3;
  SynthCapture with, without;
  ASSERT_TRUE(SynthesizeCapture(scene, o, &with).ok());
  o.exposure_jitter = 0;
  ASSERT_TRUE(SynthesizeCapture(scene, o, &without).ok());
  for (int i = 0; i < 3; ++i) {
    const double ratio = cv::mean(with.frames_bgr[i])[1] / cv::mean(without.frames_bgr[i])[1];
    EXPECT_NEAR(ratio, with.exposure_gains[i], 0.03) << i;
  }
}

TEST(Movers, AppearInFramesButNotInTheWrittenScene) {
  const Scene scene = Room();
  SynthOptions o = RoomOptions(6, 160, 120);
  SynthCapture plan;
  ASSERT_TRUE(PlanSynthCapture(scene, o, &plan).ok());
  // A yellow sphere 1.2 m in front of the camera at frame 3, moving sideways.
  const Rigid3d world_from_cam = plan.true_poses[3].cam_from_world.Inverse();
  MoverOptions sphere;
  sphere.radius_m = 0.2;
  sphere.start = world_from_cam * Eigen::Vector3d(-0.1, 0, 1.2);
  sphere.end = world_from_cam * Eigen::Vector3d(0.1, 0, 1.2);
  sphere.period_frames = 12;
  o.movers = {sphere};
  o.random_movers = 1;
  SynthCapture capture, clean;
  ASSERT_TRUE(SynthesizeCapture(scene, o, &capture).ok());
  ASSERT_EQ(capture.movers.size(), 2u);
  o.movers.clear();
  o.random_movers = 0;
  ASSERT_TRUE(SynthesizeCapture(scene, o, &clean).ok());
  Eigen::Vector2d pixel;
  ASSERT_TRUE(capture.camera.Project(
      capture.true_poses[3].cam_from_world * MoverCentreAt(sphere, 3), &pixel));
  const cv::Point p(static_cast<int>(std::lround(pixel.x())),
                    static_cast<int>(std::lround(pixel.y())));
  const cv::Vec3b bgr = capture.frames_bgr[3].at<cv::Vec3b>(p);
  EXPECT_GT(bgr[2], 160);  // yellow: strong red and green, little blue
  EXPECT_GT(bgr[1], 130);
  EXPECT_LT(bgr[0], 60);
  EXPECT_GT(cv::norm(capture.frames_bgr[3].at<cv::Vec3b>(p), clean.frames_bgr[3].at<cv::Vec3b>(p)),
            60.0);
  // The automatically placed mover is in view in some frames and keeps clear of the camera.
  const MoverOptions& placed = capture.movers[1];
  for (int f = 0; f < 6; ++f) {
    EXPECT_GT((MoverCentreAt(placed, f) - capture.true_poses[f].cam_from_world.Centre()).norm(),
              placed.radius_m);
  }

  // Written: the frames have the movers, scene.gltf does not.
  const std::string dir = MakeTempDir("synth-movers");
  o.movers = {sphere};
  ASSERT_TRUE(WriteSynthCapture(scene, o, dir, SynthWriteOptions()).ok());
  Scene written;
  ASSERT_TRUE(LoadGltfScene(dir + "/scene.gltf", SceneLoadOptions(), &written).ok());
  EXPECT_EQ(written.mesh.NumTriangles(), scene.mesh.NumTriangles());
  EXPECT_EQ(written.textures.size(), scene.textures.size());
  const cv::Mat frame = cv::imread(dir + "/frames/000003.png", cv::IMREAD_COLOR);
  ASSERT_FALSE(frame.empty());
  EXPECT_EQ(cv::norm(frame, capture.frames_bgr[3], cv::NORM_INF), 0.0);
  EXPECT_TRUE(fs::is_regular_file(dir + "/truth/movers.json"));
}

TEST(Writer, FolderLoadsAsAProjectWithAPoseForEveryFrame) {
  const Scene scene = Room();
  SynthOptions o = RoomOptions(5);
  o.lens = LensModel::kOpenCV5;
  o.pose_noise_deg = 0.3;
  o.pose_noise_m = 0.02;
  const std::string dir = MakeTempDir("synth-writer");
  int progress_calls = 0;
  SynthWriteOptions w;
  w.progress = [&](int done, int total) {
    ++progress_calls;
    EXPECT_EQ(total, 5);
  };
  SynthWriteResult result;
  ASSERT_TRUE(WriteSynthCapture(scene, o, dir, w, &result).ok());
  EXPECT_EQ(progress_calls, 5);
  EXPECT_FALSE(result.skipped);

  Project project;
  const Status loaded = LoadProject(dir + "/project.json", {}, &project);
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  EXPECT_EQ(project.truth.poses, "truth/images.txt");
  Capture capture;
  const Status opened = LoadCapture(project, CaptureLoadOptions(), &capture);
  ASSERT_TRUE(opened.ok()) << opened.message();
  EXPECT_EQ(capture.truth_poses.size(), 5u);
  EXPECT_EQ(capture.scene.mesh.NumTriangles(), scene.mesh.NumTriangles());
  SynthCapture plan;
  ASSERT_TRUE(PlanSynthCapture(scene, o, &plan).ok());
  int frames = 0;
  Frame frame;
  Status status;
  while (capture.video->Next(&frame, &status)) {
    const PosedImage* pose = capture.PoseForFrame(frame);
    ASSERT_NE(pose, nullptr) << frame.name;
    const Camera* camera = capture.CameraFor(*pose);
    ASSERT_NE(camera, nullptr);
    EXPECT_EQ(camera->model, LensModel::kOpenCV5);
    EXPECT_NEAR(camera->fx, plan.camera.fx, 1e-9);
    EXPECT_NEAR(camera->k1, plan.camera.k1, 1e-12);
    EXPECT_EQ(frame.bgr.size(), cv::Size(96, 72));
    const Rigid3d& given = plan.given_poses[frame.index].cam_from_world;
    EXPECT_LT((pose->cam_from_world.Centre() - given.Centre()).norm(), 1e-9);
    EXPECT_LT(RotationDifferenceDeg(pose->cam_from_world.rotation, given.rotation), 1e-6);
    ++frames;
  }
  EXPECT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(frames, 5);
  // COLMAP cameras.txt holds the same lens.
  std::map<int, Camera> colmap;
  ASSERT_TRUE(ReadColmapCameras(dir + "/sparse/cameras.txt", &colmap).ok());
  ASSERT_EQ(colmap.size(), 1u);
  EXPECT_NEAR(colmap[1].cx, plan.camera.cx, 1e-9);
  EXPECT_NEAR(colmap[1].k3, plan.camera.k3, 1e-12);

  // Current: nothing to do. Fewer frames: rewritten, stale frames removed.
  w.progress = nullptr;
  w.skip_if_current = true;
  ASSERT_TRUE(WriteSynthCapture(scene, o, dir, w, &result).ok());
  EXPECT_TRUE(result.skipped);
  o.frames = 3;
  ASSERT_TRUE(WriteSynthCapture(scene, o, dir, w, &result).ok());
  EXPECT_FALSE(result.skipped);
  EXPECT_TRUE(fs::exists(dir + "/frames/000002.png"));
  EXPECT_FALSE(fs::exists(dir + "/frames/000003.png"));
}

TEST(Spec, BuildsJobsAndNamesBadFields) {
  SynthSpecInput input;
  input.name = "spec.json";
  input.text = R"({"scene": "builtin:cube-room", "frames": 3, "size": "64x48",
                   "path": {"kind": "orbit", "turns": 0.5}, "pose_noise_deg": 0.2})";
  SynthJob job;
  Status s = BuildSynthJob(input, &job);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(job.options.frames, 3);
  EXPECT_EQ(job.options.width, 64);
  EXPECT_EQ(job.options.path, CameraPathKind::kOrbit);
  EXPECT_EQ(job.options.turns, 0.5);
  EXPECT_EQ(job.scene.mesh.NumTriangles(), 12);
  // Overrides win.
  input.overrides = {{"frames", "5", false}, {"path.kind", "walk", true}};
  ASSERT_TRUE(BuildSynthJob(input, &job).ok());
  EXPECT_EQ(job.options.frames, 5);
  EXPECT_EQ(job.options.path, CameraPathKind::kWalk);

  struct Bad {
    const char* text;
    const char* expected;
  };
  const Bad bad[] = {
      {R"({"scene": "builtin:cube-room", "frame": 3})", "spec.json: frame: unknown key"},
      {R"({"scene": "builtin:nowhere"})", "scene.builtin"},
      {R"({"scene": "builtin:cube-room", "frames": "many"})",
       "spec.json: frames: must be an integer"},
      {R"({"scene": "builtin:cube-room", "frames": 0})", "spec.json: frames"},
      {R"({"scene": "builtin:cube-room", "path": {"kind": "fly"}})", "path.kind"},
      {R"({"scene": "builtin:cube-room", "path": {"radius": 1}})", "path.radius: unknown key"},
      {R"({"scene": "builtin:cube-room", "movers": [{"shape": "cone"}]})", "movers[0].shape"},
      {R"({"scene": "builtin:cube-room", "size": [640]})", "size"},
      {R"({"scene": "no/such/scene.gltf"})", "scene: no such file"},
      {R"({"frames": 3})", "scene: missing"},
      {R"({"scene": "builtin:cube-room",)", "not valid JSON"},
  };
  for (const Bad& b : bad) {
    input.text = b.text;
    input.overrides.clear();
    s = BuildSynthJob(input, &job);
    ASSERT_FALSE(s.ok()) << b.text;
    EXPECT_NE(s.message().find(b.expected), std::string::npos) << s.message();
    EXPECT_EQ(s.message().find('\n'), std::string::npos) << s.message();
  }
}

TEST(Spec, BundledProjectSpecsParse) {
  for (const char* name : {"cube-room", "street"}) {
    const std::string spec = testing::SourceDir() + "/projects/" + name + "/synth.json";
    SynthJob job;
    const Status s = LoadSynthJob(spec, {}, &job);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_GE(job.options.frames, 60) << name;
    EXPECT_EQ(fs::path(job.out_dir).filename(), "capture");
    Project project;
    const Status p =
        LoadProject(testing::SourceDir() + "/projects/" + name + "/project.json", {}, &project);
    EXPECT_TRUE(p.ok()) << p.message();
  }
}

TEST(Cli, SynthWritesAProject) {
  const std::string dir = MakeTempDir("synth-cli") + "/capture";
  const auto r = RunFresco({"synth", "--scene", "builtin:cube-room", "--out", dir, "--frames", "8",
                            "--size", "160x120", "--lens", "opencv5", "--movers", "1",
                            "--pose-noise-deg", "0.2", "--seed", "4"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f :
       {"project.json", "camera.cameramodel", "sparse/cameras.txt", "sparse/images.txt",
        "truth/images.txt", "scene.gltf", "frames/000000.png", "frames/000007.png"}) {
    EXPECT_TRUE(fs::is_regular_file(dir + "/" + f)) << f;
  }
  EXPECT_FALSE(fs::exists(dir + "/frames/000008.png"));
  Project project;
  ASSERT_TRUE(LoadProject(dir + "/project.json", {}, &project).ok());
  const cv::Mat frame = cv::imread(dir + "/frames/000000.png");
  EXPECT_EQ(frame.size(), cv::Size(160, 120));
  // Again with --if-changed: nothing to do.
  const auto again = RunFresco({"synth", "--scene", "builtin:cube-room", "--out", dir, "--frames",
                                "8", "--size", "160x120", "--lens", "opencv5", "--movers", "1",
                                "--pose-noise-deg", "0.2", "--seed", "4", "--if-changed"});
  EXPECT_EQ(again.exit_code, 0) << again.err;
  EXPECT_NE(again.out.find("nothing to do"), std::string::npos) << again.out;
}

TEST(Cli, SynthBadInputExits2WithOneLine) {
  const std::string dir = MakeTempDir("synth-cli-bad");
  const std::string spec = dir + "/bad.json";
  testing::WriteText(spec, R"({"scene": "builtin:cube-room", "frames": -4})");
  const std::vector<std::vector<std::string>> cases = {
      {"synth", "--scene", "builtin:cube-room", "--out", dir, "--frames", "abc"},
      {"synth", "--scene", "builtin:castle", "--out", dir},
      {"synth", "--scene", dir + "/missing.gltf", "--out", dir},
      {"synth", "--scene", "builtin:cube-room", "--out", dir, "--size", "0x0"},
      {"synth", "--scene", "builtin:cube-room", "--out", dir, "--path", "fly"},
      {"synth", "--scene", "builtin:cube-room", "--out", dir, "--bogus"},
      {"synth", "--scene", "builtin:cube-room"},
      {"synth", "--out", dir},
      {"synth", dir + "/no-such-spec.json", "--out", dir},
      {"synth", spec, "--out", dir},
  };
  for (const auto& c : cases) {
    const auto r = RunFresco(c);
    EXPECT_EQ(r.exit_code, 2) << c[2] << " " << r.err;
    EXPECT_FALSE(r.err.empty());
    EXPECT_LE(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err;  // message [+ usage]
  }
  const auto spec_error = RunFresco({"synth", spec, "--out", dir});
  EXPECT_NE(spec_error.err.find("bad.json: frames"), std::string::npos) << spec_error.err;
  const auto help = RunFresco({"synth", "--help"});
  EXPECT_EQ(help.exit_code, 0);
  for (const char* option :
       {"--scene", "--out", "--frames", "--size", "--lens", "--path", "--movers",
        "--pose-noise-deg", "--pose-noise-m", "--exposure", "--seed", "--if-changed"}) {
    EXPECT_NE(help.out.find(option), std::string::npos) << option;
  }
}

}  // namespace
}  // namespace fresco
