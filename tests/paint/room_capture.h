// The painting tests' usual capture: a handheld camera (320x240, 70 deg) at 1.5 m height
// circling the centre of the procedural cube room (MakeCubeRoomScene) at `radius_m`.
#pragma once

#include "pipeline/core/scene.h"
#include "pipeline/synth/synthesize.h"

namespace fresco::testing {

SynthOptions HandheldRoomCapture(int frames, double radius_m);
// The handheld capture (half a turn, 0.5 m radius, tilted 20 degrees, seed 5) with four
// movers going back and forth in front of the walls (the paper's fig. 6), and the frames'
// exposure jittered by `exposure_jitter`.
SynthOptions RoomCaptureWithMovers(int frames, double exposure_jitter);
// The procedural cube room (512-texel feature textures, default size and seed).
Scene RoomScene();

}  // namespace fresco::testing
