// A painting session over a synthetic capture, as the painting tests set one up: the
// capture's camera and true poses as the session's expectations, frames painted at their
// true poses.
#pragma once

#include <cstddef>
#include <memory>

#include "pipeline/core/scene.h"
#include "pipeline/paint/mover_masks.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/synth/blocks_scene.h"
#include "pipeline/synth/synthesize.h"

namespace fresco::testing {

// The session for `capture` painting `scene` with `options`; a failure to create it fails
// the calling test (and returns null).
std::unique_ptr<PaintSession> SessionForCapture(const Scene& scene, const SynthCapture& capture,
                                                const PipelineOptions& options);

// Paints the capture's frame `i` at its true pose.
void PaintCaptureFrame(PaintSession* session, const SynthCapture& capture, size_t i,
                       FrameReport* report);

// The capture's movers found across views (mover_masks.h), at its true poses; a failure fails
// the calling test.
MoverMaskResult FindCaptureMovers(const Scene& scene, const SynthCapture& capture,
                                  const MoverMaskOptions& options = MoverMaskOptions());

// Paints every frame of the capture at its true pose; the painted scene.
Scene PaintAllFrames(const Scene& scene, const SynthCapture& capture,
                     const PipelineOptions& options);

// Half a turn (320x240) around the blocks scene `blocks`, looking at 0.3 of its tallest box's
// height from 0.6 of its ground's size away and half of it up.
SynthOptions BlocksHalfOrbit(const BlocksOptions& blocks, int frames, int seed);

}  // namespace fresco::testing
