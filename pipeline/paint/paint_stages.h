// The stages every frame goes through, in this order: the one list PaintSession::PaintFrame
// runs. Each stage is a PaintSession member `void NameStage(FrameWork* work)` (declared from
// this list) defined in its own file, which decides whether it runs for the frame (its
// setting, the `auto` modes), does its work over the buffers seen and appends its
// StageReport to work->report. FrameWork (paint_session.h) is what the stages of one frame
// hand each other: the view, the buffers in the frustum and seen, the paint statistics.
//
// Adding a stage: write `pipeline/paint/NAME_stage.cc` defining `PaintSession::NameStage`
// (its options beside it: `NAME_options.h`, see docs/architecture.md) and add one line
// below where it belongs in the order.
#pragma once

#define FRESCO_PAINT_STAGES(STAGE)                                                           \
  STAGE(Depth)      /* depth_stage.cc: the model's depth from the frame's camera (§3.3) */  \
  STAGE(Warp)       /* warp_stage.cc: each texel projected, tested and sampled (§3.2) */    \
  STAGE(Refine)     /* refine_stage.cc: registered to what the buffers hold (§3.5) */       \
  STAGE(Exposure)   /* select_stages.cc: the frame's gain against the buffers */             \
  STAGE(Background) /* background_stage.cc: movers masked (§3.4) */                         \
  STAGE(Layers)     /* layers_stage.cc: the view-dependent layer of the frame's direction */ \
  STAGE(Select)     /* select_stages.cc: painted texels keep a better stored sample */       \
  STAGE(Paint)      /* paint_stage.cc: the base buffers updated (eq. 4) */
