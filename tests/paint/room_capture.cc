#include "tests/paint/room_capture.h"

#include <cstdlib>

#include "pipeline/synth/movers.h"
#include "pipeline/synth/procedural_scenes.h"

namespace fresco::testing {

SynthOptions HandheldRoomCapture(int frames, double radius_m) {
  SynthOptions o;
  o.frames = frames;
  o.width = 320;
  o.height = 240;
  o.hfov_deg = 70;
  o.path = CameraPathKind::kHandheld;
  o.target = Eigen::Vector3d(0, 1.5, 0);
  o.radius_m = radius_m;
  o.height_m = 1.5;
  return o;
}

SynthOptions RoomCaptureWithMovers(int frames, double exposure_jitter) {
  SynthOptions o = HandheldRoomCapture(frames, 0.5);
  o.turns = 0.5;
  o.look_at_target = false;
  o.tilt_deg = 20;
  // The paper's fig. 6: objects moving in front of the walls while the camera looks around.
  auto mover = [](MoverShape shape, double radius_m, cv::Vec3b rgb, Eigen::Vector3d start,
                  Eigen::Vector3d end, double period_frames, double phase) {
    MoverOptions m;
    m.shape = shape;
    m.radius_m = radius_m;
    m.rgb = rgb;
    m.start = start;
    m.end = end;
    m.period_frames = period_frames;
    m.phase = phase;
    m.spin_deg_per_frame = shape == MoverShape::kBox ? 4.0 : 0.0;
    return m;
  };
  o.movers = {
      mover(MoverShape::kSphere, 0.25, {255, 220, 0}, {-1.4, 1.2, 1.3}, {1.4, 1.2, 1.3}, 24, 0),
      mover(MoverShape::kBox, 0.2, {220, 40, 30}, {1.3, 0.8, -1.4}, {1.3, 0.8, 1.4}, 30, 0.3),
      mover(MoverShape::kSphere, 0.2, {40, 80, 230}, {-1.3, 1.9, -1.3}, {1.3, 1.9, -1.3}, 20, 0.6),
      mover(MoverShape::kBox, 0.25, {30, 160, 60}, {-1.3, 0.6, 1.2}, {-1.3, 0.6, -1.2}, 28, 0.1),
  };
  o.exposure_jitter = exposure_jitter;
  o.seed = 5;
  return o;
}

Scene RoomScene() {
  CubeRoomOptions room;
  room.procedural_texture_px = 512;
  Scene scene;
  if (!MakeCubeRoomScene(room, &scene).ok()) std::abort();  // also linked by benchmarks
  return scene;
}

}  // namespace fresco::testing
