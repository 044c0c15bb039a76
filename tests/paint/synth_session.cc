#include "tests/paint/synth_session.h"

#include <gtest/gtest.h>

#include "pipeline/render/renderer.h"

namespace fresco::testing {

std::unique_ptr<PaintSession> SessionForCapture(const Scene& scene, const SynthCapture& capture,
                                                const PipelineOptions& options) {
  PaintSessionInputs inputs;
  inputs.scene = &scene;
  inputs.pipeline = options;
  inputs.typical_camera = &capture.camera;
  for (const auto& p : capture.true_poses) inputs.expected_poses.push_back(p.cam_from_world);
  std::unique_ptr<PaintSession> session;
  const Status status = PaintSession::Create(inputs, &session);
  EXPECT_TRUE(status.ok()) << status.message();
  return session;
}

void PaintCaptureFrame(PaintSession* session, const SynthCapture& capture, size_t i,
                       FrameReport* report) {
  Frame frame;
  frame.index = static_cast<int>(i);
  frame.bgr = capture.frames_bgr[i];
  session->PaintFrame(frame, capture.camera, capture.true_poses[i].cam_from_world, report);
}

MoverMaskResult FindCaptureMovers(const Scene& scene, const SynthCapture& capture,
                                  const MoverMaskOptions& options) {
  std::vector<MoverMaskFrame> frames;
  for (size_t i = 0; i < capture.frames_bgr.size(); ++i)
    frames.push_back({capture.frames_bgr[i], &capture.camera,
                      CamFromLocal(scene, capture.true_poses[i].cam_from_world)});
  MoverMaskResult found;
  const Status status = FindMoverMasks(scene.mesh, frames, options, &found);
  EXPECT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(found.masks.size(), frames.size());
  return found;
}

Scene PaintAllFrames(const Scene& scene, const SynthCapture& capture,
                     const PipelineOptions& options) {
  std::unique_ptr<PaintSession> session = SessionForCapture(scene, capture, options);
  FrameReport report;
  for (size_t i = 0; i < capture.frames_bgr.size(); ++i)
    PaintCaptureFrame(session.get(), capture, i, &report);
  return session->PaintedScene();
}

SynthOptions BlocksHalfOrbit(const BlocksOptions& blocks, int frames, int seed) {
  SynthOptions o;
  o.frames = frames;
  o.width = 320, o.height = 240;
  o.path = CameraPathKind::kOrbit;
  o.target = Eigen::Vector3d(0, 0.3 * blocks.max_height_m, 0);
  o.radius_m = 0.6 * blocks.ground_m;
  o.height_m = 0.5 * blocks.ground_m;
  o.turns = 0.5;
  o.seed = seed;
  return o;
}

}  // namespace fresco::testing
