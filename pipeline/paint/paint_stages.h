// The stages every frame goes through, in this order: the one list PaintSession::PaintFrame
// runs. Each stage is a PaintSession member `void NameStage(FrameWork* work)` (declared from
// this list) defined in its own file, which decides whether it runs for the frame (its
// setting, the `auto` modes), does its work over the buffers seen and appends its
// StageReport to work->report. FrameWork (paint_session.h) is what the stages of one frame
// hand each other: the view, the buffers in the frustum and seen, the paint statistics.
//
// Adding a stage: write `pipeline/paint/NAME_stage.cc` defining `PaintSession::NameStage`
// (its options in `pipeline/settings/NAME_options.h`, see docs/architecture.md) and add one
// line below where it belongs in the order. A stage between Warp and Paint that looks at the
// warped samples also adds the settings under which it runs to StagesReadWarpedSamples below:
// otherwise the warp paints the frame itself and the stage sees nothing.
#pragma once

#include "pipeline/settings/pipeline_options.h"

#define FRESCO_PAINT_STAGES(STAGE)                                                           \
  STAGE(Depth)      /* depth_stage.cc: the model's depth from the frame's camera (§3.3) */  \
  STAGE(Warp)       /* warp_stage.cc: each texel projected, tested and sampled (§3.2) */    \
  STAGE(Refine)     /* refine_stage.cc: registered to what the buffers hold (§3.5) */       \
  STAGE(Exposure)   /* select_stages.cc: the frame's gain against the buffers */             \
  STAGE(Background) /* background_stage.cc: movers masked (§3.4) */                         \
  STAGE(Layers)     /* layers_stage.cc: the view-dependent layer of the frame's direction */ \
  STAGE(Select)     /* select_stages.cc: painted texels keep a better stored sample */       \
  STAGE(Paint)      /* paint_stage.cc: the base buffers updated (eq. 4) */

namespace fresco {

// Whether the exposure and select stages run: pipeline.select.enabled, with `update: quality`
// and refinement off (refinement registers each frame to the buffers and moves them; keeping
// stored samples would keep the offsets it corrects: on refine_paint_test's capture it
// recovered 60 % of the PSNR lost to pose noise instead of 75 %).
bool SelectActive(const PipelineOptions& options);  // select_stages.cc

// The fused warp-paint path: when no stage between Warp and Paint runs on the warped samples
// (and no debug images are wanted), the warp paints them directly, the same texels without
// writing and reading back the warped images (warp_stage.cc). One line per stage that reads
// or changes the samples, with the settings under which it runs.
inline bool StagesReadWarpedSamples(const PipelineOptions& options) {
  return options.refine.mode != RefineMode::kOff ||          // Refine
         SelectActive(options) ||                            // Exposure and Select
         options.background.mode != BackgroundMode::kOff ||  // Background
         options.layers.count > 0;                           // Layers
}

}  // namespace fresco
