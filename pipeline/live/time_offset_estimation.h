// The search for the time offset between a tracker's clock and a camera's: the offset with
// which the frames, posed at `t_video + offset`, agree best with one another. How a
// candidate is scored (painting the window: pipeline/run/offset_estimator.h) is given to the
// search, so the live inputs stay below the painter.
//
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

// Scores one candidate offset (lower is better; NaN when it could not be scored).
using ScoreOffset = std::function<TimeOffsetCandidate(double offset_s)>;

// The search over candidates around options.centre_s; `frames`: the window, in capture order
// (timestamps on the video clock; their spacing sets the coarse step when step_s is 0).
TimeOffsetEstimate SearchTimeOffset(const std::vector<Frame>& frames,
                                    const TimeOffsetOptions& options, const ScoreOffset& score);

}  // namespace fresco
