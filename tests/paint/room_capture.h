// The painting tests' usual capture: a handheld camera (320x240, 70 deg) at 1.5 m height
// circling the centre of the procedural cube room (MakeCubeRoomScene) at `radius_m`.
#pragma once

#include "pipeline/core/scene.h"
#include "pipeline/synth/synthesize.h"

namespace fresco::testing {

SynthOptions HandheldRoomCapture(int frames, double radius_m);
// The procedural cube room (512-texel feature textures, default size and seed).
Scene RoomScene();

}  // namespace fresco::testing
