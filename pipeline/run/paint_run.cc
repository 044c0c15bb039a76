#include "pipeline/run/paint_run.h"

#include <cmath>

namespace fresco {

std::map<std::string, double> PaintRunStats::MeanStageMs() const {
  std::map<std::string, double> mean;
  for (const auto& [name, ms] : stage_ms_sum)
    mean[name] = frames_painted > 0 ? ms / frames_painted : 0.0;
  return mean;
}

std::map<std::string, std::map<std::string, double>> PaintRunStats::MeanStageMetrics() const {
  std::map<std::string, std::map<std::string, double>> mean;
  for (const auto& [stage, by_key] : stage_metric_sums)
    for (const auto& [key, sum_count] : by_key)
      mean[stage][key] = sum_count.first / sum_count.second;
  return mean;
}

PaintRun::PaintRun(PaintSession* session, PosedFrameSource* source, const PaintRunOptions& options)
    : session_(session), source_(source), options_(options) {
  stats_.streams.resize(source_->NumStreams());
}

FrameRead PaintRun::End(FrameRead read) {
  if (read == FrameRead::kEnded) {
    ended_ = true;
    source_->Stop();
    // `update: auto` on a capture shorter than its decision: on the frames held out so far.
    if (session_ && status_.ok()) session_->DecideUpdate();
  }
  stats_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  return read;
}

FrameRead PaintRun::Next(RunFrame* frame) {
  if (ended_) return FrameRead::kEnded;
  if (!started_) {
    started_ = true;
    start_ = std::chrono::steady_clock::now();
  }
  if (options_.max_frames > 0 && stats_.frames >= options_.max_frames) {
    max_frames_reached_ = true;
    return End(FrameRead::kEnded);
  }
  const FrameRead read = source_->Next(frame, &status_);
  if (read != FrameRead::kFrame) return End(read);
  frame->counter = stats_.frames++;
  StreamRunStats& stream = stats_.streams[frame->stream];
  ++stream.frames;
  if (frame->skipped) {  // a shard's frame that meets none of its buffers (shard.h)
    frame->fate = FrameFate::kSkipped;
    ++stats_.frames_skipped;
    ++stream.skipped;
    if (session_) session_->SkipFrame();
    return End(FrameRead::kFrame);
  }
  status_ = ApplyFramePolicy(*frame, source_->Origin(frame->stream), &frame->fate);
  if (!status_.ok()) return End(FrameRead::kEnded);
  const int every = options_.holdout_every;
  if (frame->fate == FrameFate::kNoPose) {
    ++stats_.frames_without_pose;
    ++stream.without_pose;
  } else if ((every > 0 && frame->counter % every == every / 2) ||
             frame->counter == options_.holdout_counter) {
    frame->fate = FrameFate::kHeldOut;
    ++stats_.frames_held_out;
  }
  return End(FrameRead::kFrame);
}

bool PaintRun::Save(PaintRunState* state) const {
  if (!source_->Tell(&state->position)) return false;
  state->stats = stats_;
  state->painting = session_->SaveState();
  return true;
}

Status PaintRun::Restore(const PaintRunState& state) {
  status_ = source_->Seek(state.position);
  ended_ = !status_.ok();
  if (ended_) return status_;
  max_frames_reached_ = false;
  const double seconds = stats_.seconds;  // the clock runs on
  stats_ = state.stats;
  stats_.seconds = seconds;
  session_->RestoreState(*state.painting);
  return status_;
}

std::string PaintRun::EndReason() const {
  if (max_frames_reached_)
    return "pipeline.max_frames (" + std::to_string(options_.max_frames) + ") reached";
  return source_->EndReason();
}

void PaintRun::Paint(const RunFrame& frame, FrameReport* report) {
  const Frame& f = frame.posed.frame;
  if (options_.naive)
    session_->PaintFrameNaive(f, *frame.camera, frame.posed.cam_from_world, report);
  else
    session_->PaintFrame(f, *frame.camera, frame.posed.cam_from_world, frame.stream, report);
  if (!report->painted) return;
  ++stats_.frames_painted;
  StreamRunStats& stream = stats_.streams[frame.stream];
  ++stream.painted;
  stream.texels_observed += report->background.texels_observed;
  stream.texels_masked += report->background.texels_masked;
  for (const StageReport& stage : report->stages) {
    stats_.stage_ms_sum[stage.name] += stage.wall_ms;
    for (const auto& [key, value] : stage.metrics) {
      if (!std::isfinite(value)) continue;
      auto& [sum, count] = stats_.stage_metric_sums[stage.name][key];
      sum += value, ++count;
    }
  }
}

namespace {

// RunToEnd's loop: the first error of the run or of a hook; ok at the end or when stopped.
Status RunFrames(PaintRun* run, const PaintRunHooks& hooks) {
  const auto stopped = [&] { return hooks.stop && hooks.stop(); };
  RunFrame frame;
  FrameReport report;
  while (!stopped()) {
    const FrameRead read = run->Next(&frame);
    if (read == FrameRead::kEnded) return run->status();
    if (read == FrameRead::kWaiting) continue;
    if (stopped()) break;  // arrived while the frame was read
    const bool paint = frame.fate == FrameFate::kPaint;
    if (paint && hooks.before_paint) FRESCO_RETURN_IF_ERROR(hooks.before_paint(frame));
    if (paint) run->Paint(frame, &report);
    const FrameReport* painted = paint && report.painted ? &report : nullptr;
    if (hooks.after_frame) FRESCO_RETURN_IF_ERROR(hooks.after_frame(frame, painted));
  }
  return Status::Ok();
}

}  // namespace

Status RunToEnd(PaintRun* run, const PaintRunHooks& hooks) {
  const Status status = RunFrames(run, hooks);
  run->source().Stop();  // stopped, or a hook failed: no more reading
  return status;
}

}  // namespace fresco
