// The refinement scenario shared by refine_paint_test (accuracy) and refine_bench (speed
// against accuracy): a textured room seen by a handheld camera (320x240, 70 deg, half a turn)
// whose given poses carry rotation noise, painted with given pipeline options and measured
// against the true scene by virtual rephotography at the true poses.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "pipeline/paint/paint_session.h"
#include "pipeline/synth/synthesize.h"

namespace fresco::testing {

struct RefineScenario {
  Scene scene;
  SynthCapture capture;
};

// `frames` at 30 fps; `pose_noise_deg` RMS rotation noise on the given poses.
Status MakeRefineScenario(int frames, double pose_noise_deg, RefineScenario* scenario,
                          int seed = 11);

struct PaintedScenario {
  std::unique_ptr<PaintSession> session;
  Scene scene;
  double refine_before_px = 0, refine_after_px = 0;  // mean over frames with inliers
  int refined = 0;                                   // buffer registrations applied
  double refine_ms = 0, total_ms = 0;                // per frame: the refine stage, all
};

// Paints every frame from `given` poses (true_poses or given_poses of the capture);
// `each_frame`, when given, sees every frame's report.
Status PaintScenario(const RefineScenario& scenario, const std::vector<PosedImage>& given,
                     const PipelineOptions& options, PaintedScenario* painted,
                     const std::function<void(const FrameReport&)>& each_frame = nullptr);

// Mean PSNR of the painted model against the original at the true poses (every 6th frame).
double ScenarioPsnr(const RefineScenario& scenario, const Scene& painted);

// Misalignment of painted buffers against those painted at the true poses: each buffer is
// registered to its perfect twin (robust refinement); RMS displacement of the inlier corners
// before any correction, texels, over all buffers.
double MisalignmentPx(const PaintSession& session, const PaintSession& perfect);

}  // namespace fresco::testing
