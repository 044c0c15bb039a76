// The paint stage (paint_stages.h): the persistent base buffers updated from the warped
// samples where the background stage did not mask them, by the update policy (eq. 4,
// paint_update.h); its figures (texels written, kept because sharper, the difference to what
// the buffers held).
#include <chrono>
#include <string>

#include "pipeline/paint/paint_session.h"
#include "pipeline/paint/stage_clock.h"

namespace fresco {

cv::Mat PaintSession::KeptOutOfPainting(size_t b) const {
  if (options_.background.mode == BackgroundMode::kOff || b >= background_frame_.size())
    return cv::Mat();
  const BackgroundFrame& frame = background_frame_[b];
  if (frame.near_movers > 0) return frame.kept_out;
  return frame.masked == 0 ? cv::Mat() : frame.foreground;
}

void PaintSession::PaintStage(FrameWork* work) {
  const auto start = std::chrono::steady_clock::now();
  StageReport report;
  report.name = "paint";
  const bool background = options_.background.mode != BackgroundMode::kOff;
  long long written = 0, rejected = 0, compared = 0;
  double difference_sum = 0;
  const std::vector<size_t> seen = Indices(work->seen);
  if (work->paint_in_warp) {
    report.notes["painted"] = "during the warp (no stage between them)";
  } else {
    ForEachBuffer(seen, false, [&](size_t b) {
      const cv::Mat mask = KeptOutOfPainting(b);
      const cv::Mat warming = !background || background_frame_[b].warming_up == 0
                                  ? cv::Mat()
                                  : background_frame_[b].warming;
      work->paint_stats[b] =
          PaintBuffer(set_.buffers[b], warped_[b], mask, options_, &painted_[b], warming,
                      work->held_out);
    });
  }
  for (size_t b : seen) {
    const PaintUpdateStats& stats = work->paint_stats[b];
    written += stats.written;
    rejected += stats.rejected;
    compared += stats.compared;
    difference_sum += stats.abs_grey_difference_sum;
    if (work->debug) report.images["painted_b" + std::to_string(b)] = painted_[b].bgra.clone();
  }
  report.metrics["texels_written"] = static_cast<double>(written);
  report.metrics["texels_kept_sharper"] = static_cast<double>(rejected);
  // Mean |grey difference| between this frame and what the buffers held, where both exist:
  // a cheap misalignment signal (pose error, exposure change, movers), NaN when none.
  PaintFigures& figures = work->report->paint;
  if (compared > 0) figures.difference_to_buffer = difference_sum / compared;
  figures.PutInto(&report);
  report.metrics["coverage"] = Coverage();
  report.wall_ms = MsSince(start);
  work->report->stages.push_back(std::move(report));
}

}  // namespace fresco
