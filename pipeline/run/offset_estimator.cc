#include "pipeline/run/offset_estimator.h"

#include <cmath>
#include <limits>
#include <memory>

#include "pipeline/core/capture.h"

namespace fresco {

PipelineOptions EstimationPipeline(const PipelineOptions& pipeline) {
  PipelineOptions p = pipeline;
  p.background.mode = BackgroundMode::kOff;
  p.refine.mode = RefineMode::kOff;
  p.update = UpdatePolicy::kLatest;
  p.update_every = 1;
  p.debug_images = false;
  return p;
}

TimeOffsetCandidate ScoreTimeOffset(const std::vector<Frame>& frames, const Camera& camera,
                                    const PoseAtTime& pose_at, double offset_s,
                                    PaintSession* session) {
  TimeOffsetCandidate c;
  c.offset_s = offset_s;
  session->ResetPainting();
  double sum = 0;
  FrameReport report;
  for (const Frame& frame : frames) {
    Rigid3d cam_from_world;
    if (!pose_at(frame.timestamp_s + offset_s, &cam_from_world)) continue;
    session->PaintFrame(frame, camera, cam_from_world, &report);
    if (!report.painted || !std::isfinite(report.paint.difference_to_buffer)) continue;
    sum += report.paint.difference_to_buffer;
    ++c.frames_scored;
  }
  c.score = c.frames_scored > 0 ? sum / c.frames_scored : std::numeric_limits<double>::quiet_NaN();
  return c;
}

TimeOffsetEstimate EstimateTimeOffset(const std::vector<Frame>& frames, const Camera& camera,
                                      const PoseAtTime& pose_at, const TimeOffsetOptions& options,
                                      PaintSession* session, const std::string& video) {
  for (const Frame& frame : frames) {
    if (Status size = CheckFrameSize(frame, camera, video); !size.ok()) {
      TimeOffsetEstimate refused;
      refused.offset_s = options.centre_s;
      refused.frames = static_cast<int>(frames.size());
      refused.note = size.message();
      return refused;
    }
  }
  return SearchTimeOffset(frames, options, [&](double offset_s) {
    return ScoreTimeOffset(frames, camera, pose_at, offset_s, session);
  });
}

OffsetEstimator MakeTimeOffsetEstimator(const Scene* scene, const Camera& camera,
                                        const PipelineOptions& pipeline,
                                        const GroupingOptions& grouping, double texel_size_m,
                                        const TimeOffsetOptions& options,
                                        const std::string& video) {
  return [=](const std::vector<Frame>& window, const PoseAtTime& pose_at, double centre_s,
             double search_s) {
    PaintSessionInputs inputs;
    inputs.scene = scene;
    inputs.pipeline = EstimationPipeline(pipeline);
    inputs.pipeline.texel_size_m = texel_size_m;
    inputs.grouping = grouping;
    inputs.typical_camera = &camera;
    std::unique_ptr<PaintSession> session;
    TimeOffsetOptions around = options;
    around.centre_s = centre_s;
    around.search_s = search_s;
    TimeOffsetEstimate failed;
    failed.offset_s = centre_s;
    if (Status s = PaintSession::Create(inputs, &session); !s.ok()) {
      failed.note = s.message();
      return failed;
    }
    return EstimateTimeOffset(window, camera, pose_at, around, session.get(), video);
  };
}

}  // namespace fresco
