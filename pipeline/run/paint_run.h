// A painting job: frames from a source (posed_frame_source.h), judged by the frame policy
// (frame_policy.h), painted into a PaintSession, with the run's statistics (frames read,
// painted, without a pose, held out; per stream; per-stage milliseconds and metrics). The
// one frame loop under `fresco run`, `fresco bench`, `fresco rephoto`, `fresco eval` and the
// app's worker (the frames held out are scored by pipeline/rephoto/holdout_scorer.h):
//
//   PaintRun run(session, source, options);
//   RunFrame frame;
//   while (run.Next(&frame) == FrameRead::kFrame)     // kWaiting: live, nothing yet
//     if (frame.fate == FrameFate::kPaint) run.Paint(frame, &report);
//   if (!run.status().ok()) ...                       // bad input: one line naming the file
//
// or RunToEnd() with hooks. The client decides what to do around each frame (progress,
// debug images, recording, the app's review render); what a frame counts as, and which
// frames end the run, is decided here once.
#pragma once

#include <chrono>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pipeline/paint/paint_session.h"
#include "pipeline/paint/painting_state.h"
#include "pipeline/paint/stage_report.h"
#include "pipeline/run/frame_policy.h"
#include "pipeline/run/posed_frame_source.h"

namespace fresco {

struct PaintRunOptions {
  // Frames of all streams to read at most; 0: every frame.
  int max_frames = 0;
  // Every holdout_every-th frame read (the frame counter k with k % holdout_every ==
  // holdout_every / 2) that has a pose is held out of painting (`fresco bench` scores
  // them); 0: none.
  int holdout_every = 0;
  // The frame with this counter (0-based position among the frames read), when it has a
  // pose, is held out too (`fresco rephoto` leaves one frame out per run); -1: none.
  int holdout_counter = -1;
  // Paint with PaintSession::PaintFrameNaive (the baseline `fresco bench` measures).
  bool naive = false;
};

struct RunFrame : SourcedFrame {
  FrameFate fate = FrameFate::kNoPose;
  int counter = -1;  // 0-based position among the frames this run read (all streams)
};

// Frames read, painted and without a pose, of one stream; what its background stage saw.
struct StreamRunStats {
  int frames = 0;
  int painted = 0;
  int without_pose = 0;
  int skipped = 0;  // a shard's frames not read: their view meets none of its buffers
  // Summed over the stream's painted frames (BackgroundFigures; 0 when the stage was off).
  long long texels_observed = 0;  // texels the background stage classified
  long long texels_masked = 0;    // ... masked as foreground
  // texels_masked / texels_observed; NaN when the background stage saw none.
  double MaskedFraction() const {
    return texels_observed > 0 ? static_cast<double>(texels_masked) / texels_observed
                               : std::numeric_limits<double>::quiet_NaN();
  }
};

struct PaintRunStats {
  int frames = 0;                       // read (all streams)
  int frames_painted = 0;               // painted (PaintSession said so: FrameReport::painted)
  int frames_without_pose = 0;          // skipped for want of a pose
  int frames_held_out = 0;              // held out of painting (PaintRunOptions::holdout_every)
  int frames_skipped = 0;               // a shard's frames not read (FrameFate::kSkipped)
  double seconds = 0.0;                 // wall time from the first read to the last
  std::vector<StreamRunStats> streams;  // per stream, in Project::Streams() order
  // Per stage: milliseconds summed over the painted frames.
  std::map<std::string, double> stage_ms_sum;
  // Per stage and metric: sum and count over the painted frames where it was finite.
  std::map<std::string, std::map<std::string, std::pair<double, int>>> stage_metric_sums;

  // Frames read per second of wall time (0 before any time passed).
  double Fps() const { return seconds > 0 ? frames / seconds : 0.0; }
  // Painted frames per second.
  double PaintFps() const { return seconds > 0 ? frames_painted / seconds : 0.0; }
  // Mean milliseconds per painted frame of each stage (0 when none was painted).
  std::map<std::string, double> MeanStageMs() const;
  // Each stage's metrics, averaged over the painted frames where they were finite.
  std::map<std::string, std::map<std::string, double>> MeanStageMetrics() const;
};

// A run between two frames (PaintRun::Save): the session's painting state, the counts so far
// and where the source stands; Restore goes back (or on) to it.
struct PaintRunState {
  std::shared_ptr<const PaintSession::State> painting;
  PaintRunStats stats;
  SourcePosition position;
  size_t bytes() const { return painting ? painting->bytes : 0; }
};

class PaintRun {
 public:
  // `session` and `source` must outlive the run.
  PaintRun(PaintSession* session, PosedFrameSource* source, const PaintRunOptions& options);

  // Reads the next frame and decides its fate (frame policy; held out). kFrame: to paint
  // (fate kPaint: call Paint), or counted already (kNoPose, kHeldOut). kEnded: the source
  // ended, max_frames were read, or bad input (status()); the source is stopped then.
  FrameRead Next(RunFrame* frame);
  // Paints a frame Next gave with fate kPaint into the session and counts it.
  void Paint(const RunFrame& frame, FrameReport* report);

  // The run as it stands, to come back to; false for a source that cannot go back (live).
  bool Save(PaintRunState* state) const;
  // Back (or on) to a state this run saved: painting on gives what it gave from there. An
  // error (a video that cannot be read again) leaves the run ended with it.
  Status Restore(const PaintRunState& state);

  const Status& status() const { return status_; }
  bool ended() const { return ended_; }
  // Why the run ended without an error: "pipeline.max_frames (N) reached", or the source's
  // reason ("end of video", "live video ended: ...").
  std::string EndReason() const;
  const PaintRunStats& stats() const { return stats_; }
  PosedFrameSource& source() { return *source_; }
  PaintSession& session() { return *session_; }

 private:
  FrameRead End(FrameRead read);
  PaintSession* session_;
  PosedFrameSource* source_;
  PaintRunOptions options_;
  PaintRunStats stats_;
  Status status_;
  bool ended_ = false;
  bool max_frames_reached_ = false;
  bool started_ = false;
  std::chrono::steady_clock::time_point start_;
};

// What a client does around each frame of RunToEnd (each may be empty).
struct PaintRunHooks {
  // Asked before each read and after it: true stops the run (no error; e.g. Ctrl-C).
  std::function<bool()> stop;
  // Before a frame with fate kPaint is painted (e.g. recording it); an error ends the run.
  std::function<Status(const RunFrame& frame)> before_paint;
  // After every frame read (report: the frame's report when it was painted, else null);
  // an error ends the run.
  std::function<Status(const RunFrame& frame, const FrameReport* report)> after_frame;
};

// Next + Paint until the source ends, bad input, a hook's error or a stop. Returns the
// run's status (or the hook's error); stopped runs return ok.
Status RunToEnd(PaintRun* run, const PaintRunHooks& hooks);

}  // namespace fresco
