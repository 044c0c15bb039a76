// Estimates the time offset between a tracker's clock and a camera's from the data: the
// offset with which the frames, warped into the base buffers with the poses interpolated at
// `t_video + offset`, agree best with the buffers they paint.
//
// For each candidate offset the window's frames are painted from scratch, in order, into a
// session with background learning and refinement off and `latest` updates; each frame's
// score is the mean |grey difference| between its warp and what the earlier frames painted
// (PaintSession's `difference_to_buffer`), and a candidate's score is the mean over frames.
// A wrong offset moves each frame's warp by the camera's motion over the error; as the
// motion changes from frame to frame (a hand-held camera) the warps stop agreeing.
// Candidates: a coarse scan at one frame period over +-search_s, then a fine scan at a
// quarter period around the best, then a parabola through the best fine score and its
// neighbours.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "pipeline/core/camera.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/video_source.h"
#include "pipeline/paint/paint_session.h"

namespace fresco {

struct TimeOffsetOptions {
  double centre_s = 0.0;  // the configured offset (tracker clock minus video clock)
  double search_s = 0.5;  // candidates within centre_s +- search_s
  double step_s = 0.0;    // coarse step; 0 = the frames' median interval
  int min_frames = 4;     // a candidate scored on fewer frames is not trusted

  bool Check() const { return search_s > 0 && step_s >= 0 && min_frames >= 2; }
};

struct TimeOffsetCandidate {
  double offset_s = 0.0;
  double score = 0.0;  // mean |grey difference| (lower is better); NaN when not scored
  int frames_scored = 0;
};

struct TimeOffsetEstimate {
  bool ok = false;
  double offset_s = 0.0;  // the estimate (ok), else the centre
  double score = 0.0;     // at the best candidate
  // The score's rise from the best to the median candidate: how pronounced the minimum is.
  double contrast = 0.0;
  int frames = 0;                               // frames used
  double seconds = 0.0;                         // wall time of the estimation
  std::vector<TimeOffsetCandidate> candidates;  // every candidate tried, in order tried
  std::string note;                             // why not ok
};

// cam_from_world at tracker time `t`; false when unknown.
using PoseAtTime = std::function<bool(double t, Rigid3d* cam_from_world)>;

// `frames`: the window, in capture order (timestamps on the video clock). `session` is
// repainted for every candidate (ResetPainting); give one made for this (background off,
// refinement off, update latest: see EstimationPipeline()).
TimeOffsetEstimate EstimateTimeOffset(const std::vector<Frame>& frames, const Camera& camera,
                                      const PoseAtTime& pose_at, const TimeOffsetOptions& options,
                                      PaintSession* session);

// The pipeline settings the estimation paints with, from the project's.
PipelineOptions EstimationPipeline(const PipelineOptions& pipeline);

// Scores one candidate offset (exposed for tests).
TimeOffsetCandidate ScoreTimeOffset(const std::vector<Frame>& frames, const Camera& camera,
                                    const PoseAtTime& pose_at, double offset_s,
                                    PaintSession* session);

}  // namespace fresco
