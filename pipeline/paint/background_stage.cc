// The background stage (paint_stages.h): each visible texel compared with its background
// model, learned from this stream's earlier frames; movers masked out of painting (§3.4,
// background_model.h). Off with pipeline.background.mode off.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/paint/mover_masks.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/paint/stage_clock.h"

namespace fresco {
namespace {

// The session's first frames, where refinement's `auto` has nothing to measure yet (it
// measures a frame against what the frames before it painted; in the evaluation suites it
// first measures the third): while it is deciding, the movers found across views are kept
// out of painting there. Keeping them out until it has measured (up to 4 frames where it never
// can) lost 0.53 dB on a castle photo, whose 10 photos are too far apart to measure.
constexpr int kMoversKeptOutFirstFrames = 2;

}  // namespace

void PaintSession::BackgroundStage(FrameWork* work) {
  if (options_.background.mode == BackgroundMode::kOff) return;
  work->report->stages.push_back(
      SegmentForeground(work->seen, work->stream, work->debug, work->frame->movers, &work->view,
                        work->number < kMoversKeptOutFirstFrames, &work->report->background));
}

StageReport PaintSession::SegmentForeground(const std::vector<bool>& seen, int stream, bool debug,
                                            const cv::Mat& movers, const FrameView* view,
                                            bool first_frames, BackgroundFigures* figures) {
  const auto start = std::chrono::steady_clock::now();
  StageReport report;
  report.name = "background";
  std::vector<BufferBackground>& models = StreamBackground(stream);
  float gain = 1.0f;
  if (options_.background.mode == BackgroundMode::kRobust && options_.background.normalize_gain) {
    // One histogram per buffer seen, in parallel, summed in buffer order (integer counts:
    // the same whatever the threads).
    const std::vector<size_t> seen_buffers = Indices(seen);
    long long visible = 0;
    for (size_t b : seen_buffers) visible += warped_[b].visible;
    const int stride = GainStride(visible);
    std::vector<GainHistogram> per_buffer(seen_buffers.size());
    cv::parallel_for_(
        cv::Range(0, static_cast<int>(seen_buffers.size())), [&](const cv::Range& range) {
          for (int i = range.start; i < range.end; ++i) {
            const size_t b = seen_buffers[i];
            models[b].AccumulateGain(set_.buffers[b], warped_[b], stride, &per_buffer[i]);
          }
        });
    GainHistogram histogram;
    for (const GainHistogram& h : per_buffer) {
      for (int i = 0; i < GainHistogram::kBins; ++i) histogram.bins[i] += h.bins[i];
      histogram.count += h.count;
    }
    gain = histogram.MedianGain();
  }
  long long observed = 0, raw = 0, masked = 0, warming = 0, blobs = 0, near_movers = 0;
  const std::vector<size_t> seen_list = Indices(seen);
  // Growing by colour spreads whatever was flagged: misaligned edges too. `auto` grows once
  // the refinement's `auto` has measured the frames and found them aligned (not when it
  // decided off for want of a measurement, as with a few photos far apart).
  const GrowMode grow_mode = options_.background.grow;
  const AutoDecision& aligned = refine_auto_.decision();
  const bool grow = grow_mode == GrowMode::kOn ||
                    (grow_mode == GrowMode::kAuto && aligned.state == AutoDecision::State::kOff &&
                     aligned.frames_measured > 0 && std::isfinite(aligned.evidence));
  // The movers found across views (Frame::movers) join the foreground as growth does, once
  // the frames are found aligned: between photos far apart (a castle's 10, where refinement
  // cannot measure) the masks are mostly the mesh's error, and joining them lost up to 1.2 dB
  // on a photo. Where they join, whatever else they cover is kept out of painting too (a pixel
  // that differs from most frames that see its surface point shows a mover, or the background
  // beside one, which a later frame paints), and already while refinement's `auto` is still
  // deciding, in the first frames (kMoversKeptOutFirstFrames) and once it has measured a
  // frame: the first frames' movers are the ones that stay. Without growth, keeping them out
  // painted more of the movers in background_test's room.
  const bool have_movers = !movers.empty() && view && view->camera;
  const bool with_movers = grow && have_movers;
  const bool deciding_measured = aligned.state == AutoDecision::State::kDeciding &&
                                 aligned.frames_measured > 0 && std::isfinite(aligned.evidence);
  const bool deciding_first = aligned.state == AutoDecision::State::kDeciding && first_frames;
  const bool keep_out = with_movers || (have_movers && (deciding_measured || deciding_first) &&
                                        grow_mode == GrowMode::kAuto);
  if (keep_out) WarpMovers(seen_list, movers, *view);  // keep_out includes with_movers
  ForEachBuffer(seen_list, false, [&](size_t b) {
    BackgroundFrame& frame = background_frame_[b];
    models[b].Update(set_.buffers[b], warped_[b], gain, debug, grow, &frame,
                     with_movers ? &mover_texels_[b] : nullptr,
                     with_movers ? &agreed_texels_[b] : nullptr);
    if (keep_out && cv::countNonZero(mover_texels_[b]) > 0) {
      cv::bitwise_or(frame.foreground, mover_texels_[b], frame.foreground);
      frame.masked = cv::countNonZero(frame.foreground & warped_[b].valid);
    }
    // The margin's texels outside the foreground (the model's Update reset the rest).
    frame.near_movers = keep_out ? cv::countNonZero(near_mover_texels_[b] & ~frame.foreground) : 0;
    if (frame.near_movers > 0)
      cv::bitwise_or(frame.foreground, near_mover_texels_[b], frame.kept_out);
  });
  for (size_t b : seen_list) {
    const BackgroundFrame& frame = background_frame_[b];
    observed += frame.observed, raw += frame.foreground_raw, masked += frame.masked;
    warming += frame.warming_up, blobs += frame.blobs_removed, near_movers += frame.near_movers;
    if (debug) {
      const std::string suffix = "_b" + std::to_string(b);
      report.images["model" + suffix] = models[b].Image(set_.buffers[b]);
      report.images["difference" + suffix] = frame.difference;
      report.images["foreground" + suffix] = frame.foreground;
    }
  }
  report.metrics["gain"] = gain;
  figures->texels_observed = observed;
  figures->texels_masked = masked;
  figures->PutInto(&report);
  report.metrics["texels_foreground_raw"] = static_cast<double>(raw);
  report.metrics["texels_warming_up"] = static_cast<double>(warming);
  report.metrics["warming_fraction"] = observed > 0 ? static_cast<double>(warming) / observed : 0.0;
  report.metrics["blobs_removed"] = static_cast<double>(blobs);
  report.metrics["texels_near_movers"] = static_cast<double>(near_movers);
  report.metrics["grown"] = grow ? 1.0 : 0.0;
  report.wall_ms = MsSince(start);
  return report;
}

void PaintSession::WarpMovers(const std::vector<size_t>& seen_list, const cv::Mat& movers,
                              const FrameView& view) {
  const cv::Size size(view.camera->width, view.camera->height);
  // The margin around the movers, at the masks' own size (they are made at a reduced size).
  cv::Mat near = cv::Mat::zeros(movers.size(), CV_8U);
  const int margin = static_cast<int>(
      std::lround(options_.background.mover_margin * std::max(movers.cols, movers.rows)));
  if (margin > 0) {
    const cv::Mat mover = movers == kMoverPixel;
    cv::dilate(
        mover, near,
        cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * margin + 1, 2 * margin + 1)));
    near &= ~mover;
  }
  cv::Mat full = movers, bgr;
  if (full.size() != size) {
    cv::resize(movers, full, size, 0, 0, cv::INTER_NEAREST);
    cv::resize(near, near, size, 0, 0, cv::INTER_NEAREST);
  }
  // Nearest sampling carries the values unchanged: the packed mask in the first channel, the
  // margin in the second.
  cv::merge(std::vector<cv::Mat>{full, near, full}, bgr);
  FrameView movers_view = view;
  movers_view.frame_bgr = &bgr;
  movers_view.pyramid.clear();
  WarpOptions nearest;
  nearest.sampling = SamplingMode::kNearest;
  nearest.occlusion = options_.occlusion;
  movers_warped_.resize(set_.buffers.size());
  mover_texels_.resize(set_.buffers.size());
  agreed_texels_.resize(set_.buffers.size());
  near_mover_texels_.resize(set_.buffers.size());
  ForEachBuffer(seen_list, false, [&](size_t b) {
    WarpedBuffer& warped = movers_warped_[b];
    WarpFrameToBuffer(set_.buffers[b], movers_view, nearest, &warped);
    cv::Mat values;  // kMoverPixel, kAgreedPixel or 0 (nearest: no value in between)
    cv::extractChannel(warped.bgr, values, 0);
    mover_texels_[b] = (values == kMoverPixel) & warped.valid;
    agreed_texels_[b] = (values == kAgreedPixel) & warped.valid;
    cv::extractChannel(warped.bgr, values, 1);
    near_mover_texels_[b] = (values > 0) & warped.valid;
  });
}

}  // namespace fresco
