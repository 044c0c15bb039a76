// The painting pipeline against ground truth: synthesize a capture of a known scene with
// known poses, paint it, re-render the painted model and compare with rendering the
// original model, at the frames' poses and at novel poses.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/image_metrics.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/render/renderer.h"
#include "pipeline/synth/procedural_scenes.h"
#include "pipeline/synth/synthesize.h"
#include "tests/paint/rephotograph.h"
#include "tests/paint/room_capture.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

struct PaintResult {
  std::unique_ptr<PaintSession> session;
  Scene painted;
};

PaintResult Paint(const Scene& scene, const SynthCapture& capture, PipelineOptions options,
                  bool use_true_poses = true) {
  PaintResult result;
  PaintSessionInputs inputs;
  inputs.scene = &scene;
  inputs.pipeline = options;
  inputs.typical_camera = &capture.camera;
  for (const auto& p : capture.true_poses) inputs.expected_poses.push_back(p.cam_from_world);
  EXPECT_TRUE(PaintSession::Create(inputs, &result.session).ok());
  FrameReport report;
  for (size_t i = 0; i < capture.frames_bgr.size(); ++i) {
    Frame frame;
    frame.index = static_cast<int>(i);
    frame.bgr = capture.frames_bgr[i];
    const auto& poses = use_true_poses ? capture.true_poses : capture.given_poses;
    result.session->PaintFrame(frame, capture.camera, poses[i].cam_from_world, &report);
  }
  result.painted = result.session->PaintedScene();
  return result;
}

using Comparison = testing::Rephoto;

Comparison Compare(const Scene& original, const Scene& painted, const Camera& camera,
                   const Rigid3d& cam_from_world) {
  return testing::Rephotograph(testing::RephotoRenderer(camera), original, painted, cam_from_world);
}

SynthOptions RoomCapture(int frames) {
  SynthOptions o = testing::HandheldRoomCapture(frames, 0.8);
  o.seed = 3;
  return o;
}

Scene Room() { return testing::RoomScene(); }

TEST(Grouping, CubeRoomHasOneBufferPerFace) {
  const Scene scene = Room();
  const Grouping g = ComputeGrouping(scene.mesh, ComputeAdjacency(scene.mesh), 20.0);
  EXPECT_EQ(g.groups.size(), 6u);
}

TEST(Grouping, EditsMergeSplitMoveAndNameBadEdits) {
  const Scene scene = MakeTexturedCubeScene(1.0);
  Grouping g = ComputeGrouping(scene.mesh, ComputeAdjacency(scene.mesh), 20.0);
  ASSERT_EQ(g.groups.size(), 6u);
  GroupingEdit merge;
  merge.op = "merge";
  merge.groups = {0, 1};
  ASSERT_TRUE(ApplyGroupingEdits({merge}, scene.mesh.NumTriangles(), &g).ok());
  EXPECT_EQ(g.groups.size(), 5u);
  GroupingEdit split;
  split.op = "split";
  split.triangles = {g.groups[0].triangles[0]};
  ASSERT_TRUE(ApplyGroupingEdits({split}, scene.mesh.NumTriangles(), &g).ok());
  EXPECT_EQ(g.groups.size(), 6u);
  GroupingEdit bad;
  bad.op = "merge";
  bad.groups = {0, 42};
  const Status s = ApplyGroupingEdits({bad}, scene.mesh.NumTriangles(), &g);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("grouping.edits[0]: group 42"), std::string::npos) << s.message();
}

// A plane facing the camera at one texel per pixel, texel centres on pixel centres (a
// static camera filling its view): every texel is painted, the border ring included, whose
// centres project exactly onto the border pixels' centres (stored points are quantized, so
// they land a rounding error outside).
TEST(BaseBuffers, TexelsOnTheBorderPixelsCentresArePainted) {
  const int w = 160, h = 120;
  const double focal_px = 200.0, distance_m = 5.0, s = distance_m / focal_px;
  const Camera camera = Camera::FromParams(LensModel::kPinhole, w, h,
                                           {focal_px, focal_px, 0.5 * (w - 1), 0.5 * (h - 1)});
  const Scene scene = MakeTexturedPlaneScene(w * s, h * s);
  const Rigid3d cam_from_world(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX())),
                               Eigen::Vector3d(0, 0, distance_m));
  PaintSessionInputs inputs;
  inputs.scene = &scene;
  inputs.pipeline.texel_size_m = s;
  std::unique_ptr<PaintSession> session;
  ASSERT_TRUE(PaintSession::Create(inputs, &session).ok());
  ASSERT_EQ(session->NumSurfaceTexels(), w * h);
  Frame frame;
  frame.bgr = cv::Mat(h, w, CV_8UC3, cv::Scalar(40, 120, 200));
  FrameReport report;
  session->PaintFrame(frame, camera, cam_from_world, &report);
  const StageReport* paint = report.Stage("paint");
  ASSERT_NE(paint, nullptr);
  EXPECT_EQ(paint->metrics.at("coverage"), 1.0);
}

TEST(BaseBuffers, TexelPointsLieOnTheSurfaceAndCoverIt) {
  const Scene scene = MakeTexturedCubeScene(1.0);
  const Grouping g = ComputeGrouping(scene.mesh, ComputeAdjacency(scene.mesh), 20.0);
  BaseBufferOptions options;
  options.texel_size_m = 0.01;
  const BaseBufferSet set = BuildBaseBuffers(scene.mesh, g, options);
  ASSERT_EQ(set.buffers.size(), 6u);
  for (const BaseBuffer& b : set.buffers) {
    // A 1 m face at 1 cm texels: 100 x 100 texel centres inside.
    EXPECT_NEAR(b.num_surface_texels, 10000, 200);
    // Every texel's point on the plane of one of the buffer's triangles, with that
    // triangle's normal (points and normals are stored quantized to 16 bits).
    for (int k = 0; k < b.NumTexels(); ++k) {
      const Eigen::Vector3d p = b.Point(k).cast<double>();
      double best = std::numeric_limits<double>::infinity();
      int owner = -1;
      for (int t : b.triangles) {
        const double d = std::abs((p - scene.mesh.Corner(t, 0)).dot(scene.mesh.Normal(t)));
        if (d < best) best = d, owner = t;
      }
      ASSERT_GE(owner, 0);
      EXPECT_NEAR(best, 0.0, 1e-5);
      EXPECT_NEAR((b.Normal(k).cast<double>() - scene.mesh.Normal(owner)).norm(), 0.0, 1e-4);
    }
  }
}

TEST(BaseBuffers, FoldedGroupIsSplit) {
  // Two parallel faces facing the same way, stacked: one group from an explicit merge, but
  // one projection cannot serve both (they overlap in the buffer).
  Scene scene = MakeTexturedPlaneScene(1.0, 1.0);
  const int n = scene.mesh.NumTriangles();
  const int v0 = static_cast<int>(scene.mesh.vertices.size());
  for (int v = 0; v < v0; ++v)
    scene.mesh.vertices.push_back(scene.mesh.vertices[v] + Eigen::Vector3d(0, 0, -0.5));
  for (int t = 0; t < n; ++t) {
    scene.mesh.triangles.push_back(scene.mesh.triangles[t] + Eigen::Vector3i::Constant(v0));
    scene.mesh.uvs.push_back(scene.mesh.uvs[t]);
    scene.mesh.material.push_back(scene.mesh.material[t]);
    scene.mesh.has_uv.push_back(scene.mesh.has_uv[t]);
  }
  Grouping g;
  g.groups.resize(1);
  for (int t = 0; t < 2 * n; ++t) g.groups[0].triangles.push_back(t);
  g.RebuildIndex(2 * n);
  BaseBufferOptions options;
  options.texel_size_m = 0.02;
  const BaseBufferSet set = BuildBaseBuffers(scene.mesh, g, options);
  EXPECT_EQ(set.buffers.size(), 2u);
  EXPECT_GE(set.folds_split, 1);
  // Laid out again from the recipes (as a shard does from the pre-pass file's layout): the
  // same buffers, hollow, then each built alone with the same texels.
  BufferLayout layout;
  layout.texel_size_m = options.texel_size_m;
  layout.folds_split = set.folds_split;
  layout.recipes = set.recipes;
  const BaseBufferSet hollow = HollowBaseBuffers(scene.mesh, layout, options);
  ASSERT_EQ(hollow.buffers.size(), set.buffers.size());
  EXPECT_TRUE(hollow.grouping.groups == set.grouping.groups);
  for (size_t b = 0; b < set.buffers.size(); ++b) {
    const BaseBuffer& want = set.buffers[b];
    for (const BaseBuffer& got :
         {hollow.buffers[b], BuildLaidOutBuffer(scene.mesh, hollow, b, options)}) {
      EXPECT_EQ(got.triangles, want.triangles) << b;
      EXPECT_EQ(got.width, want.width) << b;
      EXPECT_EQ(got.height, want.height) << b;
      EXPECT_EQ(got.origin, want.origin) << b;
      EXPECT_EQ(got.bounds_min, want.bounds_min) << b;
      EXPECT_EQ(got.num_surface_texels, want.num_surface_texels) << b;
    }
    EXPECT_EQ(hollow.buffers[b].NumTexels(), 0);
    const BaseBuffer built = BuildLaidOutBuffer(scene.mesh, hollow, b, options);
    EXPECT_EQ(built.texel_index, want.texel_index) << b;
    EXPECT_EQ(built.point_qx, want.point_qx) << b;
    EXPECT_EQ(built.normal_qz, want.normal_qz) << b;
  }
}

TEST(Painting, PerfectPosesReproduceTheSceneAtFramePosesAndNovelPoses) {
  const Scene scene = Room();
  SynthCapture capture;
  ASSERT_TRUE(SynthesizeCapture(scene, RoomCapture(24), &capture).ok());
  PipelineOptions options;
  const PaintResult r = Paint(scene, capture, options);
  EXPECT_EQ(r.session->buffers().size(), 6u);
  for (int i : {0, 11, 23}) {
    const Comparison c =
        Compare(scene, r.painted, capture.camera, capture.true_poses[i].cam_from_world);
    EXPECT_GE(c.psnr_db, 30.0) << "frame " << i;
    EXPECT_GE(c.completeness, 0.95) << "frame " << i;
  }
  // A novel pose between frames (looking where the path looked).
  SynthOptions novel_options = RoomCapture(24);
  novel_options.seed = 3;
  SynthCapture novel;
  novel_options.frames = 24;
  ASSERT_TRUE(SynthesizeCapture(scene, novel_options, &novel).ok());
  const Rigid3d& a = capture.true_poses[5].cam_from_world;
  const Rigid3d& b = capture.true_poses[6].cam_from_world;
  const Rigid3d mid(a.rotation.slerp(0.5, b.rotation), 0.5 * (a.translation + b.translation));
  const Comparison c = Compare(scene, r.painted, capture.camera, mid);
  EXPECT_GE(c.psnr_db, 30.0);
  EXPECT_GE(c.completeness, 0.9);
}

TEST(Painting, BackFacesAreNotPainted) {
  // A plane facing +Z seen from -Z: nothing may be painted.
  const Scene scene = MakeTexturedPlaneScene(2.0, 2.0);
  Camera camera = Camera::FromParams(LensModel::kPinhole, 160, 120, {150, 150, 79.5, 59.5});
  SynthCapture capture;
  capture.camera = camera;
  // Camera at z = -2 looking towards +Z (camera z forward = world +Z), y down = world -Y.
  PosedImage pose;
  pose.cam_from_world =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ())),
              Eigen::Vector3d(0, 0, 2));
  capture.true_poses = {pose};
  capture.frames_bgr = {cv::Mat(120, 160, CV_8UC3, cv::Scalar(0, 0, 255))};
  PipelineOptions options;
  options.texel_size_m = 0.02;
  const PaintResult r = Paint(scene, capture, options);
  EXPECT_EQ(r.session->NumPaintedSurfaceTexels(), 0);
  // The same frame from the front paints most of what it sees.
  capture.true_poses[0].cam_from_world =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX())),
              Eigen::Vector3d(0, 0, 2));
  const PaintResult front = Paint(scene, capture, options);
  EXPECT_GT(front.session->NumPaintedSurfaceTexels(), 1000);
}

TEST(Painting, OccludedSurfacesAreNotPainted) {
  // A cube in front of a wall: from the camera the wall behind the cube must stay unpainted.
  Scene scene = MakeTexturedPlaneScene(4.0, 4.0);  // wall at z = 0 facing +Z
  const Scene cube = MakeTexturedCubeScene(0.6);
  const int v0 = static_cast<int>(scene.mesh.vertices.size());
  for (const auto& v : cube.mesh.vertices)
    scene.mesh.vertices.push_back(v + Eigen::Vector3d(0, 0, 1.0));
  const int m0 = static_cast<int>(scene.materials.size());
  const int t0 = static_cast<int>(scene.textures.size());
  for (auto m : cube.materials) {
    if (m.base_color_texture >= 0) m.base_color_texture += t0;
    scene.materials.push_back(m);
  }
  for (const auto& t : cube.textures) scene.textures.push_back(t);
  for (int t = 0; t < cube.mesh.NumTriangles(); ++t) {
    scene.mesh.triangles.push_back(cube.mesh.triangles[t] + Eigen::Vector3i::Constant(v0));
    scene.mesh.uvs.push_back(cube.mesh.uvs[t]);
    scene.mesh.material.push_back(cube.mesh.material[t] + m0);
    scene.mesh.has_uv.push_back(cube.mesh.has_uv[t]);
  }
  const Camera camera = Camera::FromParams(LensModel::kPinhole, 160, 120, {120, 120, 79.5, 59.5});
  SynthCapture capture;
  capture.camera = camera;
  PosedImage pose;  // at z = 4 looking at -Z: rotate 180 deg about X (y down = world -Y)
  pose.cam_from_world =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX())),
              Eigen::Vector3d(0, 0, 4));
  capture.true_poses = {pose};
  RenderOutput frame;
  Renderer(camera, RenderOptions()).Render(scene, pose.cam_from_world, &frame);
  cv::Mat bgr;
  cv::cvtColor(frame.rgba, bgr, cv::COLOR_RGBA2BGR);
  capture.frames_bgr = {bgr};
  PipelineOptions options;
  options.texel_size_m = 0.02;
  const PaintResult r = Paint(scene, capture, options);
  // The wall's buffer: texels whose point is hidden behind the cube stay unpainted.
  const Rigid3d cam_from_local = CamFromLocal(scene, pose.cam_from_world);
  int hidden = 0, hidden_painted = 0, open = 0, open_painted = 0;
  for (size_t b = 0; b < r.session->buffers().size(); ++b) {
    const BaseBuffer& buf = r.session->buffers()[b];
    if (buf.triangles.front() >= 2) continue;  // only the wall (triangles 0, 1)
    for (int k = 0; k < buf.NumTexels(); ++k) {
      if (!buf.on_surface[k]) continue;
      Eigen::Vector2d px;
      const Eigen::Vector3d pc = cam_from_local * buf.Point(k).cast<double>();
      if (!camera.Project(pc, &px) || px.x() < 1 || px.y() < 1 || px.x() > 158 || px.y() > 118)
        continue;
      const int id = frame.triangle_id.at<int>(static_cast<int>(std::lround(px.y())),
                                               static_cast<int>(std::lround(px.x())));
      const int idx = buf.texel_index[k];
      const bool painted =
          r.session->painted()[b].bgra.at<cv::Vec4b>(idx / buf.width, idx % buf.width)[3] == 255;
      if (id >= 2) {
        ++hidden, hidden_painted += painted;
      } else if (id >= 0) {
        ++open, open_painted += painted;
      }
    }
  }
  EXPECT_GT(hidden, 100);
  EXPECT_LE(hidden_painted, hidden / 50)
      << hidden_painted << " of " << hidden;  // silhouette ring at most
  EXPECT_GE(open_painted, open * 95 / 100);
  // Without the depth test the hidden part would be painted: the test can fail.
  options.occlusion.enabled = false;
  const PaintResult no_depth = Paint(scene, capture, options);
  EXPECT_GT(no_depth.session->NumPaintedSurfaceTexels(), r.session->NumPaintedSurfaceTexels());
}

TEST(Painting, QualityPolicyKeepsTheSharperSampleLatestTakesTheNewest) {
  // A 2 x 2 m plane facing +Z, seen head-on first from 1.5 m (sharp: red frame), then from
  // 6 m (4x blurrier per texel: blue frame). Texels seen by both keep red under the quality
  // policy and turn blue under the paper's latest-wins policy.
  const Scene scene = MakeTexturedPlaneScene(2.0, 2.0);
  SynthCapture capture;
  capture.camera = Camera::FromParams(LensModel::kPinhole, 160, 120, {150, 150, 79.5, 59.5});
  const Eigen::Quaterniond facing(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  PosedImage near_pose, far_pose;
  near_pose.cam_from_world = Rigid3d(facing, Eigen::Vector3d(0, 0, 1.5));
  far_pose.cam_from_world = Rigid3d(facing, Eigen::Vector3d(0, 0, 6.0));
  capture.true_poses = {near_pose, far_pose};
  capture.frames_bgr = {cv::Mat(120, 160, CV_8UC3, cv::Scalar(0, 0, 255)),
                        cv::Mat(120, 160, CV_8UC3, cv::Scalar(255, 0, 0))};
  PipelineOptions options;
  options.texel_size_m = 0.01;  // 1.5 pixels per texel from near, 0.25 from far
  // Two frames of different colours are not a video of a static scene: the background
  // model would (rightly) mask the second one. This test is about the update policy alone.
  options.background.mode = BackgroundMode::kOff;
  auto count = [](const PaintResult& r, int channel) {
    int n = 0;
    for (const PaintedBuffer& p : r.session->painted())
      for (int y = 0; y < p.bgra.rows; ++y)
        for (int x = 0; x < p.bgra.cols; ++x) {
          const cv::Vec4b px = p.bgra.at<cv::Vec4b>(y, x);
          n += px[3] == 255 && px[channel] == 255;
        }
    return n;
  };
  options.update = UpdatePolicy::kQuality;
  const PaintResult quality = Paint(scene, capture, options);
  options.update = UpdatePolicy::kLatest;
  const PaintResult latest = Paint(scene, capture, options);
  // From near the camera sees about 1.6 x 1.2 m of the plane: ~19000 texels.
  const int red_quality = count(quality, 2), blue_quality = count(quality, 0);
  const int red_latest = count(latest, 2), blue_latest = count(latest, 0);
  EXPECT_GT(red_quality, 15000);
  EXPECT_EQ(red_latest, 0);  // the far frame sees the whole plane: all blue
  EXPECT_GT(blue_latest, red_quality);
  EXPECT_EQ(quality.session->NumPaintedSurfaceTexels(), latest.session->NumPaintedSurfaceTexels());
  EXPECT_EQ(red_quality + blue_quality, red_latest + blue_latest);
}

TEST(Painting, MapScaleCoordinatesPaintAsWellAsTheOrigin) {
  const Scene scene = Room();
  SynthCapture capture;
  ASSERT_TRUE(SynthesizeCapture(scene, RoomCapture(8), &capture).ok());
  PipelineOptions options;
  const PaintResult near = Paint(scene, capture, options);
  // Shift the world by ~1e6 m: scene origin and poses move together.
  const Eigen::Vector3d shift(1.0e6, 30.0, -2.0e6);
  Scene far_scene = scene;
  far_scene.origin_in_world += shift;
  SynthCapture far_capture = capture;
  for (auto& p : far_capture.true_poses)
    p.cam_from_world.translation -= p.cam_from_world.rotation * shift;
  const PaintResult far = Paint(far_scene, far_capture, options);
  EXPECT_EQ(far.session->NumPaintedSurfaceTexels(), near.session->NumPaintedSurfaceTexels());
  const Comparison cn =
      Compare(scene, near.painted, capture.camera, capture.true_poses[4].cam_from_world);
  const Comparison cf =
      Compare(far_scene, far.painted, capture.camera, far_capture.true_poses[4].cam_from_world);
  EXPECT_NEAR(cf.psnr_db, cn.psnr_db, 0.2);
}

}  // namespace
}  // namespace fresco
