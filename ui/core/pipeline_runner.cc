#include "ui/core/pipeline_runner.h"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <string>

#include <opencv2/imgproc.hpp>

#include "pipeline/core/capture.h"
#include "pipeline/core/scaled_camera.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/render/renderer.h"
#include "pipeline/run/frame_policy.h"
#include "pipeline/run/paint_job.h"
#include "ui/core/job_estimate.h"

namespace fresco {

struct PipelineRunner::Session {
  Project project;
  // The project opened for painting as `fresco run` opens it (pipeline/run/paint_job.h): one
  // capture per stream (the scene in [0]), the PaintSession after the whole-capture pre-pass,
  // the live inputs, and the source of posed frames.
  std::unique_ptr<PaintJob> job;
  // The painting job's frame loop (reads `job`: after it), judged and counted as `fresco run`
  // does.
  std::unique_ptr<PaintRun> run;
  // Painting states to step back to (files only; RunnerOptions::snapshot_every).
  std::unique_ptr<RunSnapshots> snapshots;
  // The process's CPU seconds when the last state was saved (-1: none yet).
  double painting_since_state = -1;
  // The first live stream, whose state the Pipeline panel shows (-1: none); its state as
  // read, its recording, and the pose time of its last frame taken (-1: none yet).
  int live_stream = -1;
  LiveWatch live_watch;
  LiveRecording recording;
  double live_pose_time_s = -1;
  // Per stream: a half-size renderer through the stream's first camera, for the
  // misalignment review (null when it could not be made).
  std::vector<std::unique_ptr<Renderer>> review;
  int next_frame = 0;  // index of the next frame to read (live: frames taken so far)
  bool ended = false;
  std::string end_message;  // the status once ended ("end of video", "error: ...")

  PaintSession* paint() const { return job->session.get(); }
  const std::vector<Capture>& captures() const { return job->captures; }
  bool live() const { return live_stream >= 0; }
};

namespace {

// The process's CPU seconds so far, every thread (painting and saving use several).
double ProcessCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

// Drops the oldest half of a per-frame history once it holds 2 * keep entries (amortized
// O(1) a frame).
template <typename T>
void TrimHistory(size_t keep, std::vector<T>* history) {
  if (history->size() >= 2 * keep) history->erase(history->begin(), history->end() - keep);
}

using Clock = std::chrono::steady_clock;

// The camera at half size (pixel centres stay on the same rays).
Camera HalfSize(const Camera& camera) {
  return ScaledCamera(camera, std::max(1, camera.width / 2), std::max(1, camera.height / 2));
}

// What does not change while the job paints (SessionGeometry).
std::shared_ptr<const SessionGeometry> MakeGeometry(const PaintJob& job) {
  const PaintSession& paint = *job.session;
  auto geometry = std::make_shared<SessionGeometry>();
  geometry->painted_layout = paint.PaintedSceneByBuffer();
  geometry->painted_layout.textures.clear();  // the layout only: textures come per publish
  geometry->groups = paint.grouping().groups;
  geometry->buffer_of_triangle = paint.grouping().group_of_triangle;
  for (const BaseBuffer& b : paint.buffers()) {
    geometry->buffer_texels.push_back(b.num_surface_texels);
    geometry->buffer_texel_size_m.push_back(b.texel_size_m);
    geometry->buffer_size_texels.push_back(int64_t{b.width} * b.height);
  }
  for (const Capture& c : job.captures) {
    std::vector<Rigid3d>& path = geometry->stream_paths.emplace_back();
    for (const PosedImage& p : c.poses) path.push_back(p.cam_from_world);
    geometry->stream_cameras.push_back(c.cameras.begin()->second);
  }
  geometry->path = geometry->stream_paths[0];
  geometry->camera = geometry->stream_cameras[0];
  // A live video is not open yet, and has no end.
  geometry->num_frames = job.live ? -1 : job.source->FrameCount();
  geometry->texel_size_m = paint.default_texel_size_m();
  geometry->folds_split = paint.folds_split();
  return geometry;
}

}  // namespace

PipelineRunner::PipelineRunner(const RunnerOptions& options)
    : options_(options), snapshot_(std::make_shared<RunnerSnapshot>()) {
  working_.status = "no project";
  thread_ = std::thread([this] { Loop(); });
}

PipelineRunner::~PipelineRunner() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.clear();
  }
  Post({Command::kQuit, {}, 0, {}});
  thread_.join();
}

void PipelineRunner::Post(Command command) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(std::move(command));
  }
  wake_.notify_all();
}

void PipelineRunner::Restart(const Project& project) { Post({Command::kRestart, project, 0, {}}); }
void PipelineRunner::Play() { Post({Command::kPlay, {}, 0, {}}); }
void PipelineRunner::Pause() { Post({Command::kPause, {}, 0, {}}); }
void PipelineRunner::Step() { Post({Command::kStep, {}, 0, {}}); }
void PipelineRunner::Seek(int frame) { Post({Command::kSeek, {}, frame, {}}); }
void PipelineRunner::Record(const std::string& dir) { Post({Command::kRecord, {}, 0, dir}); }

void PipelineRunner::WaitIdle() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return queue_.empty() && !busy_; });
}

std::shared_ptr<const RunnerSnapshot> PipelineRunner::Snapshot() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return snapshot_;
}

void PipelineRunner::OpenSession(const Project& project) {
  session_.reset();
  const uint64_t geometry_version = working_.geometry_version + 1;
  working_ = RunnerSnapshot();
  working_.version = snapshot_->version;
  working_.geometry_version = geometry_version;
  auto s = std::make_unique<Session>();
  s->project = project;
  const std::vector<StreamSpec> specs = project.Streams();
  for (int i = 0; i < static_cast<int>(specs.size()) && s->live_stream < 0; ++i)
    if (IsLiveStream(project, i)) s->live_stream = i;
  if (s->live()) {
    LiveStatus& l = working_.live;
    l.active = true;
    l.state = "connecting";
    l.video = project.Resolve(specs[s->live_stream].video);
    l.poses = project.Resolve(specs[s->live_stream].poses);
    working_.status = "connecting to " + l.video + " and " + l.poses;
    Publish(false);  // opening waits for the sources (up to their timeouts)
  }
  // Opened as `fresco run` opens it: the same pre-pass, the same sources; a live source is
  // polled so that the worker stays responsive while it stalls.
  PaintJobOptions job_options;
  job_options.poll_ms = options_.live_poll_ms;
  job_options.read_frames_without_pose = true;  // shown while playing
  // Each step before painting says how far it got, how long it has run and, once that can
  // be told, about how long is left (at its pace so far).
  const auto progress = [this](const char* what) {
    auto started = std::make_shared<Clock::time_point>();
    return [this, what, started](int done, int total, const std::string&) {
      if (*started == Clock::time_point()) *started = Clock::now();
      const double elapsed_s = std::chrono::duration<double>(Clock::now() - *started).count();
      const double fraction = total > 0 ? static_cast<double>(done) / total : 0;
      // A seek back reopens the project: its progress stays a seek's.
      working_.step_text = std::string(seek_target_ >= 0 ? "seeking: " : "") + what + " " +
                           std::to_string(done) + "/" + std::to_string(total);
      working_.step_fraction = fraction;
      working_.step_started = *started;
      working_.status = working_.step_text + ", " + ElapsedAndRemainingText(elapsed_s, fraction);
      Publish(false);
    };
  };
  job_options.joint_progress = progress("adjusting poses");
  job_options.movers_progress = progress("finding movers, pass");
  // The pre-pass's reading, published at most every publish interval (a frame takes ms).
  job_options.read_progress = [this, read = progress("reading every frame"),
                               last = std::make_shared<Clock::time_point>()](
                                  int done, int total, const std::string& line) {
    if (done != total &&
        Clock::now() - *last < std::chrono::milliseconds(options_.publish_interval_ms))
      return;
    *last = Clock::now();
    read(done, total, line);
  };
  // The steps without a progress of their own: about as long as they took the last time
  // this project opened (Apply, Restart and seeks back reopen it).
  job_options.step_started = [this, &project](const std::string& step) {
    working_.status = std::string(seek_target_ >= 0 ? "seeking: " : "") + step;
    const double last_s = project.file_path != last_open_file_ ? -1
                          : step == kLoadStep                  ? last_open_.load
                                                               : last_open_.cameras;
    if (last_s >= 1) working_.status += ", about " + DurationText(last_s) + " (as last time)";
    working_.step_text = working_.status;
    working_.step_fraction = -1;
    working_.step_started = Clock::now();
    Publish(false);
  };
  if (const Status opened = OpenPaintJob(project, job_options, &s->job); !opened.ok()) {
    working_.status = "error: " + opened.message();
    if (s->live()) {
      working_.live.state = "error";
      working_.live.problem = working_.status;
    }
    return;
  }
  last_open_file_ = project.file_path;
  last_open_ = s->job->open_seconds;
  PaintRunOptions run_options;
  run_options.max_frames = project.pipeline.max_frames;
  s->run = std::make_unique<PaintRun>(s->paint(), s->job->source.get(), run_options);
  s->snapshots = std::make_unique<RunSnapshots>(
      options_.snapshot_every, static_cast<size_t>(std::max(0, options_.snapshot_budget_mb)) << 20);
  working_.geometry = MakeGeometry(*s->job);
  working_.stream_frames.assign(s->captures().size(), cv::Mat());
  for (const Camera& camera : working_.geometry->stream_cameras) {
    std::unique_ptr<Renderer>& review = s->review.emplace_back();
    if (!options_.misalignment) continue;
    try {
      review = std::make_unique<Renderer>(HalfSize(camera), RenderOptions());
    } catch (const std::exception&) {
      review.reset();
    }
  }
  working_.status = "paused";
  session_ = std::move(s);
}

PipelineRunner::Painted PipelineRunner::PaintNext(bool show) {
  if (!session_ || session_->ended) return Painted::kEnded;
  Session& s = *session_;
  if (!s.live() && options_.snapshot_budget_mb > 0 && s.snapshots->Due(s.next_frame)) {
    PaintRunState state;  // the state before this frame, to step back to
    const double started = ProcessCpuSeconds();
    if (s.run->Save(&state)) s.snapshots->Add(s.next_frame, std::move(state));
    // Its cost against the painting since the state before (CPU: the machine may be shared,
    // and a pause does not count): keeping states stays a small share of the painting.
    const double saved = ProcessCpuSeconds();
    s.snapshots->Costs(saved - started,
                       s.painting_since_state < 0 ? 0 : started - s.painting_since_state);
    s.painting_since_state = saved;
  }
  RunFrame f;
  const FrameRead read = s.run->Next(&f);  // the frame policy of `fresco run` and bench
  s.next_frame = s.run->stats().frames;
  if (read == FrameRead::kWaiting) return Painted::kWaiting;
  if (read == FrameRead::kEnded) {
    s.ended = true;
    const Status& status = s.run->status();
    s.end_message = status.ok() ? s.run->EndReason() : "error: " + status.message();
    std::string recorded;
    if (s.recording.active())  // errors: in its status
      s.recording.Finish(s.job->live_inputs[s.live_stream], &recorded);
    return Painted::kEnded;
  }
  const PosedFrame& posed = f.posed;
  const Frame& frame = posed.frame;
  // Several streams: frames are counted over all of them, as seeking counts them.
  const bool several = s.captures().size() > 1;
  working_.frame = several ? f.counter : frame.index;
  working_.frame_name =
      several ? "stream " + std::to_string(f.stream) + " " + frame.name : frame.name;
  working_.has_pose = posed.has_pose;
  working_.stream = f.stream;
  if (show) {
    working_.frame_bgr = frame.bgr.clone();
    if (static_cast<size_t>(f.stream) < working_.stream_frames.size())
      working_.stream_frames[f.stream] = working_.frame_bgr;
  }
  if (f.fate != FrameFate::kPaint) {  // no pose (the app holds no frame out)
    working_.report = FrameReport();
    working_.report.frame = frame.index;
    working_.report.skipped_reason = "no pose";
    return Painted::kFrame;
  }
  if (s.live() && f.stream == s.live_stream) s.live_pose_time_s = posed.pose_time_s;
  if (s.live()) {
    if (!several) s.recording.Add(posed);  // an error stops it: in its status
    if (working_.live_paths.size() <= static_cast<size_t>(f.stream))
      working_.live_paths.resize(f.stream + 1);
    std::vector<Rigid3d>& path = working_.live_paths[f.stream];
    path.push_back(posed.cam_from_world);
    TrimHistory(RunnerSnapshot::kLivePathFrames, &path);
  }
  working_.cam_from_world = posed.cam_from_world;
  // Review: the painted model, as it stands before this frame, seen from this frame.
  Renderer* review =
      static_cast<size_t>(f.stream) < s.review.size() ? s.review[f.stream].get() : nullptr;
  if (show && review && s.paint()->NumPaintedSurfaceTexels() > 0) {
    RenderOutput out;
    review->Render(s.paint()->PaintedSceneByBuffer(), posed.cam_from_world, &out);
    cv::Mat small, rephoto, grey_frame, grey_rephoto, diff;
    cv::resize(frame.bgr, small, out.rgba.size(), 0, 0, cv::INTER_AREA);
    cv::cvtColor(out.rgba, rephoto, cv::COLOR_RGBA2BGR);
    std::vector<cv::Mat> channels;
    cv::split(out.rgba, channels);
    const cv::Mat painted_mask = channels[3] == 255;
    cv::cvtColor(small, grey_frame, cv::COLOR_BGR2GRAY);
    cv::cvtColor(rephoto, grey_rephoto, cv::COLOR_BGR2GRAY);
    cv::absdiff(grey_frame, grey_rephoto, diff);
    diff.setTo(0, ~painted_mask);
    cv::Mat scaled;
    diff.convertTo(scaled, CV_8U, 4.0);  // 64 grey levels of difference = full scale
    cv::applyColorMap(scaled, working_.difference_heat, cv::COLORMAP_INFERNO);
    working_.difference_heat.setTo(cv::Scalar(40, 40, 40), ~painted_mask);
    rephoto.setTo(cv::Scalar(40, 40, 40), ~painted_mask);
    working_.rephoto_bgr = rephoto;
  } else if (show) {
    working_.rephoto_bgr.release();
    working_.difference_heat.release();
  }
  s.paint()->set_debug_images(show && options_.debug_images);
  s.run->Paint(f, &working_.report);
  working_.report_has_images = show && options_.debug_images;
  if (working_.report.painted) {
    working_.frames_painted.push_back(working_.frame);  // several streams: the counter
    for (const StageReport& st : working_.report.stages)
      working_.stage_ms[st.name].push_back(static_cast<float>(st.wall_ms));
    working_.misalignment.push_back(static_cast<float>(working_.report.paint.difference_to_buffer));
    if (working_.report.Stage("refine")) {
      working_.refine_before_px.push_back(
          static_cast<float>(working_.report.refine.residual_before_px));
      working_.refine_after_px.push_back(
          static_cast<float>(working_.report.refine.residual_after_px));
    }
    const size_t keep = static_cast<size_t>(std::max(1, options_.history_frames));
    TrimHistory(keep, &working_.frames_painted);
    TrimHistory(keep, &working_.misalignment);
    TrimHistory(keep, &working_.refine_before_px);
    TrimHistory(keep, &working_.refine_after_px);
    for (auto& [stage, ms] : working_.stage_ms) TrimHistory(keep, &ms);
  }
  working_.coverage = s.paint()->Coverage();
  return Painted::kFrame;
}

bool PipelineRunner::SeekBackFromSnapshot(int frame) {
  Session& s = *session_;
  int from = -1;
  const PaintRunState* state = s.snapshots->AtOrBefore(frame, &from);
  if (!state || !s.run->Restore(*state).ok()) return false;
  s.next_frame = from;
  s.ended = false;
  s.end_message.clear();
  // The histories forget the frames painted from there on (painted again).
  size_t keep = working_.frames_painted.size();
  while (keep > 0 && working_.frames_painted[keep - 1] >= from) --keep;
  const size_t drop = working_.frames_painted.size() - keep;
  const auto forget = [drop](auto* history) {
    history->resize(history->size() - std::min(drop, history->size()));
  };
  forget(&working_.frames_painted);
  forget(&working_.misalignment);
  for (auto& [stage, ms] : working_.stage_ms) forget(&ms);
  // Refinement's figures run from the first frame painted while it ran on: as many as kept.
  for (std::vector<float>* refine : {&working_.refine_before_px, &working_.refine_after_px})
    refine->resize(std::min(refine->size(), keep));
  working_.coverage = s.paint()->Coverage();
  return true;
}

void PipelineRunner::SetRecording(const std::string& dir) {
  // The panel offers Record for live sources of a project with one stream only.
  if (!session_ || !session_->live() || session_->captures().size() > 1) return;
  Session& s = *session_;
  std::string recorded;  // errors: in the recording's status
  if (dir.empty()) {
    if (s.recording.active()) s.recording.Finish(s.job->live_inputs[s.live_stream], &recorded);
  } else if (!s.ended) {
    s.recording.Start(dir, s.project.ForStream(s.live_stream));
  }
}

void PipelineRunner::Publish(bool with_painted) {
  working_.playing = playing_;
  working_.seek_target = seek_target_;
  if (session_) {  // without one, the status says why (no project, error, connecting)
    working_.run = session_->run->stats();
    working_.status = session_->ended ? session_->end_message : playing_ ? "playing" : "paused";
    if (seek_target_ >= 0 && !session_->ended) working_.status = "seeking";
    if (Session& s = *session_; s.live()) {
      const int l = s.live_stream;
      working_.live = s.live_watch.Read(s.project.ForStream(l), s.job->live_inputs[l], s.ended,
                                        s.run->status(), s.live_pose_time_s);
      s.recording.Describe(&working_.live);
      // The figures are the first live stream's: so is the count of frames painted.
      working_.live.frames_painted = s.run->stats().streams[l].painted;
      working_.live.streams = static_cast<int>(s.captures().size());
      if (!session_->ended) working_.status += " (live: " + working_.live.state + ")";
    }
  }
  if (with_painted && session_) {
    auto painted = std::make_shared<std::vector<cv::Mat>>();
    for (const PaintedBuffer& p : session_->paint()->painted()) painted->push_back(p.bgra.clone());
    working_.painted = painted;
    auto layers = std::make_shared<std::vector<RunnerSnapshot::LayerImages>>();
    for (const ViewLayer& layer : session_->paint()->view_layers()) {
      RunnerSnapshot::LayerImages images;
      images.centre_local = layer.Centre().cast<float>();
      for (const PaintedBuffer& p : layer.painted) images.bgra.push_back(p.bgra.clone());
      layers->push_back(std::move(images));
    }
    working_.layers = layers;
    ++working_.painted_version;
  }
  ++working_.version;
  auto snapshot = std::make_shared<RunnerSnapshot>(working_);
  if (options_.on_publish) options_.on_publish(*snapshot);
  std::lock_guard<std::mutex> lock(mutex_);
  snapshot_ = snapshot;
}

void PipelineRunner::Loop() {
  // An exception (out of memory on a large mesh) ends the session, not the app: the worker
  // says why in the status, as for bad input, and serves on.
  for (;;) {
    std::string failure;
    try {
      Serve();
      return;
    } catch (...) {
      failure = FailureMessage(std::current_exception());
    }
    session_.reset();
    playing_ = false;
    seek_target_ = -1;
    working_.status = "error: " + failure;
    Publish(true);
  }
}

bool PipelineRunner::Handle(Command command, Clock::time_point* last_publish) {
  switch (command.kind) {
    case Command::kQuit:
      return false;
    case Command::kRestart:
      playing_ = false;
      seek_target_ = -1;
      OpenSession(command.project);
      Publish(true);
      break;
    case Command::kPlay:
      playing_ = session_ != nullptr && !session_->ended;
      Publish(false);
      break;
    case Command::kPause:  // also stops a seek where it got to (a whole frame painted)
      playing_ = false;
      seek_target_ = -1;
      Publish(true);
      break;
    case Command::kStep:
      playing_ = false;
      if (session_ && session_->live()) {  // waits for the next frame (as a seek)
        seek_target_ = session_->ended ? -1 : session_->next_frame;
        if (seek_target_ < 0) Publish(false);
        break;
      }
      PaintNext(true);
      Publish(true);
      break;
    case Command::kRecord:
      SetRecording(command.path);
      Publish(false);
      break;
    case Command::kSeek:
      playing_ = false;
      // A live source cannot go back: only forward seeks (paint N more frames) apply.
      if (session_ && !session_->live() && command.frame < session_->next_frame) {
        // Back: from the nearest saved painting state at or before the frame, else reopen
        // and repaint from frame 0. Say so at once (going back can take seconds on large
        // buffers); progress follows as frames are painted.
        seek_target_ = command.frame;
        working_.frame = -1;
        int state_frame = -1;
        working_.seek_state =
            session_->snapshots->AtOrBefore(command.frame, &state_frame) ? state_frame : -1;
        Publish(false);
        if (!SeekBackFromSnapshot(command.frame)) {
          const Project project = session_->project;
          OpenSession(project);
        }
      }
      if (session_) working_.seek_from = session_->next_frame;
      seek_target_ = session_ ? command.frame : -1;
      if (session_ && seek_target_ < session_->next_frame) seek_target_ = -1;
      // Either the result, or that a seek is under way (the UI shows its progress).
      Publish(seek_target_ < 0);
      *last_publish = Clock::now();
      break;
  }
  return true;
}

void PipelineRunner::Serve() {
  auto last_publish = Clock::now();
  for (;;) {
    Command command{Command::kPause, {}, -1, {}};
    bool have_command = false;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      busy_ = playing_ || seek_target_ >= 0;
      if (queue_.empty() && !busy_) idle_.notify_all();
      const auto ready = [this] { return !queue_.empty() || playing_ || seek_target_ >= 0; };
      // Paused on a live source: wake up now and then to publish the sources' state.
      if (session_ && session_->live() && !session_->ended)
        wake_.wait_for(lock, std::chrono::milliseconds(options_.publish_interval_ms), ready);
      else
        wake_.wait(lock, ready);
      if (!queue_.empty()) {
        command = std::move(queue_.front());
        queue_.pop_front();
        have_command = true;
      }
      busy_ = true;
    }
    if (have_command) {
      if (!Handle(std::move(command), &last_publish)) return;
      continue;
    }
    const bool due =
        Clock::now() - last_publish >= std::chrono::milliseconds(options_.publish_interval_ms);
    if (seek_target_ >= 0) {
      const bool last = session_->next_frame >= seek_target_;
      const Painted painted = PaintNext(last);
      if (painted == Painted::kEnded || (painted == Painted::kFrame && last)) {
        seek_target_ = -1;
        Publish(true);
      } else if (due) {  // progress (or a live source's state while waiting)
        Publish(false);
        last_publish = Clock::now();
      }
      continue;
    }
    if (playing_) {
      const Painted painted = PaintNext(due);
      if (painted == Painted::kEnded) {
        playing_ = false;
        Publish(true);
      } else if (due) {
        Publish(painted == Painted::kFrame);
        last_publish = Clock::now();
      }
    } else if (due && session_ && session_->live()) {  // paused: the sources' state
      Publish(false);
      last_publish = Clock::now();
    }
  }
}

}  // namespace fresco
