// The live time-offset estimate's scoring: each candidate offset paints the window's frames
// from scratch, in order, into a session of its own with background learning and refinement
// off and `latest` updates; a frame's score is the mean |grey difference| between its warp
// and what the earlier frames painted (PaintSession's `difference_to_buffer`), a candidate's
// the mean over frames. A wrong offset moves each frame's warp by the camera's motion over
// the error; as the motion changes from frame to frame (a hand-held camera) the warps stop
// agreeing. The search over candidates is pipeline/live/time_offset_estimation.h.
//
// The window's frames are judged by the frame policy's size check before any is painted: a
// frame that is not the camera's size ends the estimate with the policy's message (not ok),
// and the frame itself then meets the policy in the run (bad input naming it).
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/camera.h"
#include "pipeline/core/project.h"
#include "pipeline/live/live_frames.h"
#include "pipeline/live/time_offset_estimation.h"
#include "pipeline/paint/paint_session.h"

namespace fresco {

// The pipeline settings the estimation paints with, from the project's.
PipelineOptions EstimationPipeline(const PipelineOptions& pipeline);

// Scores one candidate offset (exposed for tests). `session` is repainted (ResetPainting).
TimeOffsetCandidate ScoreTimeOffset(const std::vector<Frame>& frames, const Camera& camera,
                                    const PoseAtTime& pose_at, double offset_s,
                                    PaintSession* session);

// The estimate over `frames` (the window, in capture order), painting into `session` (made
// for this: EstimationPipeline()). `video` names the frames' file or address in the message
// when a frame is not the camera's size.
TimeOffsetEstimate EstimateTimeOffset(const std::vector<Frame>& frames, const Camera& camera,
                                      const PoseAtTime& pose_at, const TimeOffsetOptions& options,
                                      PaintSession* session, const std::string& video = "");

// The estimator LiveFrames runs: paints the window into its own session over `scene` seen
// through `camera`, candidates around `centre_s`; `video` as above.
OffsetEstimator MakeTimeOffsetEstimator(const Scene* scene, const Camera& camera,
                                        const PipelineOptions& pipeline,
                                        const GroupingOptions& grouping, double texel_size_m,
                                        const TimeOffsetOptions& options,
                                        const std::string& video = "");

}  // namespace fresco
