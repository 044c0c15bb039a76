#include "tests/paint/room_capture.h"

#include <cstdlib>

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

Scene RoomScene() {
  CubeRoomOptions room;
  room.procedural_texture_px = 512;
  Scene scene;
  if (!MakeCubeRoomScene(room, &scene).ok()) std::abort();  // also linked by benchmarks
  return scene;
}

}  // namespace fresco::testing
