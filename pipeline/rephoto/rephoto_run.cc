#include "pipeline/rephoto/rephoto_run.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>

#include <opencv2/core/utility.hpp>

#include "pipeline/core/project.h"
#include "pipeline/live/live_input.h"
#include "pipeline/rephoto/holdout_scorer.h"
#include "pipeline/run/paint_job.h"
#include "pipeline/run/paint_run.h"

namespace fresco {

Status RephotoOptions::Check() const {
  if (every < 1) return Status::Error("--every: must be >= 1 (got " + std::to_string(every) + ")");
  return Status::Ok();
}

namespace {

// A frame with a pose, as the first pass read it.
struct PosedFrameId {
  int counter = 0, stream = 0;
  std::string name;
};

bool Stopped(const RephotoOptions& options) { return options.stop && options.stop(); }

// Reads every frame once (no painting) and lists those the painting job would paint.
Status ListPosedFrames(const Project& project, std::vector<PosedFrameId>* posed, int* read) {
  std::unique_ptr<PaintJob> job;
  FRESCO_RETURN_IF_ERROR(OpenPaintJob(project, PaintJobOptions(), &job));
  PaintRunOptions run_options;
  run_options.max_frames = project.pipeline.max_frames;
  PaintRun run(job->session.get(), job->source.get(), run_options);
  RunFrame frame;
  while (run.Next(&frame) == FrameRead::kFrame) {
    if (frame.fate != FrameFate::kPaint) continue;
    const std::string& name = frame.pose_name.empty() ? frame.posed.frame.name : frame.pose_name;
    posed->push_back({frame.counter, frame.stream, name});
  }
  *read = run.stats().frames;
  return run.status();
}

// Paints the project without frame `id`, renders the model at its pose and scores.
Status ScoreOneOut(const Project& project, const PosedFrameId& id, const RephotoOptions& options,
                   const RephotoViewSink& sink, RephotoFrame* result) {
  std::unique_ptr<PaintJob> job;
  PaintJobOptions job_options;
  job_options.joint_holdout_counter = id.counter;  // the photo left out plays no part
  FRESCO_RETURN_IF_ERROR(OpenPaintJob(project, job_options, &job));
  PaintRunOptions run_options;
  run_options.max_frames = project.pipeline.max_frames;
  run_options.holdout_counter = id.counter;
  PaintRun run(job->session.get(), job->source.get(), run_options);
  std::optional<HeldOutFrame> left_out;
  PaintRunHooks hooks;
  hooks.stop = [&] { return Stopped(options); };
  hooks.after_frame = [&](const RunFrame& f, const FrameReport*) {
    if (f.fate == FrameFate::kHeldOut && f.counter == id.counter) left_out = HeldOutFrameOf(f);
    return Status::Ok();
  };
  FRESCO_RETURN_IF_ERROR(RunToEnd(&run, hooks));
  if (Stopped(options)) return Status::Error(project.file_path + ": interrupted");
  if (!left_out) {  // the first pass saw it: the frames changed on disk in between
    return Status::Error(project.file_path + ": frame '" + id.name +
                         "' was not read again (did the video change?)");
  }
  // With view-dependent layers (pipeline.layers) the scorer renders the model as a viewer
  // sees it: the layers blended by the direction to the left-out photo.
  HoldoutScorerOptions scorer_options;
  scorer_options.keep_views = true;
  HoldoutScorer scorer(job->session->PaintedScene(), scorer_options);
  const HeldOutScore& score = scorer.Add(*left_out);
  const RephotoView& view = score.view;
  result->name = id.name;
  result->counter = id.counter;
  result->stream = id.stream;
  result->frames_painted = run.stats().frames_painted;
  result->view_layers = static_cast<int>(scorer.painted().view_layers.size());
  result->paint_seconds = run.stats().seconds;
  result->decisions = job->session->auto_decisions();
  result->pixels = score.rephoto.pixels;
  // Nothing compared: no PSNR, uncorrelated.
  result->psnr_db =
      score.rephoto.pixels > 0 ? score.rephoto.psnr_db : std::numeric_limits<double>::quiet_NaN();
  result->one_minus_ncc = score.rephoto.pixels > 0 ? view.local_one_minus_ncc : 1.0;
  result->completeness = score.rephoto.completeness;
  result->image_coverage = view.image_coverage;
  return sink ? sink(*result, view.rendered_bgr, left_out->photo_bgr) : Status::Ok();
}

}  // namespace

Status RunRephoto(const std::string& project_path, const RephotoOptions& options,
                  const RephotoViewSink& sink, RephotoResult* result) {
  FRESCO_RETURN_IF_ERROR(options.Check());
  Project project;
  FRESCO_RETURN_IF_ERROR(LoadProject(project_path, options.overrides, &project));
  if (IsLiveProject(project)) {
    return Status::Error(project_path +
                         ": video: rephotography needs recorded frames, not a live source");
  }
  cv::setNumThreads(project.pipeline.threads > 0 ? project.pipeline.threads : -1);
  result->project = project_path;
  std::vector<PosedFrameId> posed;
  FRESCO_RETURN_IF_ERROR(ListPosedFrames(project, &posed, &result->frames_read));
  result->frames_posed = static_cast<int>(posed.size());
  if (posed.size() < 2) {
    const StreamSpec stream = project.Streams()[0];
    return Status::Error(project.Resolve(stream.poses) +
                         ": poses: rephotography needs at least 2 frames with poses (found " +
                         std::to_string(posed.size()) + " in " + project.Resolve(stream.video) +
                         ")");
  }
  std::vector<PosedFrameId> cases;
  for (size_t i = 0; i < posed.size(); i += options.every) cases.push_back(posed[i]);
  const int total = static_cast<int>(cases.size());
  for (int i = 0; i < total; ++i) {
    if (options.progress) options.progress(i, total, cases[i].name + " left out");
    RephotoFrame frame;
    FRESCO_RETURN_IF_ERROR(ScoreOneOut(project, cases[i], options, sink, &frame));
    result->frames.push_back(frame);
    if (options.progress) {
      char line[200];
      std::snprintf(line, sizeof line, "%s: %.2f dB, 1-NCC %.3f, completeness %.3f (%.1f s)",
                    frame.name.c_str(), frame.psnr_db, frame.one_minus_ncc, frame.completeness,
                    frame.paint_seconds);
      options.progress(i + 1, total, line);
    }
  }
  return Status::Ok();
}

}  // namespace fresco
