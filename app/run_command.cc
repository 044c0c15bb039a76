// fresco run PROJECT.json --out DIR [--set KEY=VALUE ...]: replays a project headless,
// paints every frame, writes DIR/painted.gltf, DIR/metrics.json and (opt-in) DIR/stages/.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <future>
#include <iostream>
#include <map>

#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>

#include "app/commands.h"
#include "app/frame_reader.h"
#include "app/interrupt.h"
#include "app/progress.h"
#include "pipeline/core/atomic_file.h"
#include "pipeline/core/capture.h"
#include "pipeline/core/image_io.h"
#include "pipeline/core/project.h"
#include "pipeline/paint/charts.h"
#include "pipeline/paint/open_project.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/live/live_input.h"
#include "pipeline/live/session_recorder.h"

namespace fresco {
namespace {

ArgSpec RunSpec() {
  ArgSpec spec;
  spec.usage =
      "fresco run PROJECT.json --out DIR [--set KEY=VALUE ...] [--debug-images] [--quiet]\n"
      "       [--record DIR]";
  spec.help =
      "Replays the project headless: streams its video, paints every frame into the base\n"
      "buffers, and writes DIR/painted.gltf (+ .bin and one PNG per texture atlas page;\n"
      "alpha 0 = never painted) and DIR/metrics.json. The outputs are written all or nothing\n"
      "at the end: a run that fails or is stopped leaves DIR as it was. Ctrl-C (or SIGTERM)\n"
      "stops between frames, keeps the outputs of earlier runs and exits 130 (143).\n\n"
      "  --set KEY=VALUE   override a project setting by JSON path, e.g.\n"
      "                    --set pipeline.sampling=nearest --set pipeline.update_every=20\n"
      "  --debug-images    write per-stage debug images under DIR/stages/ (costs time)\n"
      "  --quiet           no progress on stderr\n"
      "  --record DIR      (live sources) also write the session as a project to replay:\n"
      "                    DIR/frames/, DIR/poses.txt, DIR/project.json\n\n"
      "Live sources (README \"Live capture\"): `video` may be device:N or a stream URL\n"
      "(udp://127.0.0.1:5000, rtsp://..., http://...), `poses` a feed of TUM lines\n"
      "(tcp://HOST:PORT, udp://HOST:PORT, fifo://PATH) or a TUM file; frames match poses\n"
      "by time (+ time_offset_s, estimated with live.estimate_offset); the run ends when\n"
      "the video ends (its stream ends, or no frame within live.read_timeout_s; the\n"
      "\"live\" object in metrics.json says which in end_reason).\n\n"
      "Several streams (\"fresco\": 2, `streams`): their frames paint one model, interleaved\n"
      "by frame index (frame 0 of each stream, then frame 1 of each, ...); a stream that\n"
      "ends early leaves the others going on. pipeline.max_frames counts frames of all\n"
      "streams. Live sources need a project with one stream.";
  spec.min_positional = spec.max_positional = 1;
  spec.options = {"--out", "--record"};
  spec.repeatable = {"--set"};
  spec.switches = {"--debug-images", "--quiet"};
  spec.required = {"--out"};
  return spec;
}

struct StageTotals {
  std::map<std::string, double> ms;
  // Per stage and metric: sum and count over the frames where it was finite.
  std::map<std::string, std::map<std::string, std::pair<double, int>>> metrics;
  int frames = 0;
};

Status WriteStageImages(const std::string& dir, const FrameReport& report) {
  for (const StageReport& stage : report.stages) {
    for (const auto& [name, image] : stage.images) {
      char file[256];
      std::snprintf(file, sizeof file, "%06d_%s_%s.png", report.frame, stage.name.c_str(),
                    name.c_str());
      FRESCO_RETURN_IF_ERROR(WriteImageAtomic(dir + "/" + file, image));
    }
  }
  return Status::Ok();
}

// What the painting loop gets per frame, from files or live sources.
struct LoopFrame {
  PosedFrame posed;
  const Camera* camera = nullptr;
  int stream = 0;  // index into Project::Streams()
};
using NextLoopFrame = std::function<bool(LoopFrame*, Status*)>;

// The frames of every stream of a file replay, interleaved by frame index: frame 0 of each
// stream, then frame 1 of each, ... (what cameras recording the same period at the same
// rate give); a stream that ends leaves the others going on. Each stream is read one frame
// ahead on its own thread (FrameReader).
class InterleavedFrames {
 public:
  InterleavedFrames(const Project& project, const std::vector<Capture>& streams)
      : project_(project), specs_(project.Streams()), streams_(streams) {
    for (const Capture& stream : streams_)
      readers_.push_back(std::make_unique<FrameReader>(stream.video.get()));
    ended_.assign(streams_.size(), false);
  }

  bool Next(LoopFrame* f, Status* status) {
    for (size_t tried = 0; tried < streams_.size(); ++tried) {
      const int s = next_;
      next_ = (next_ + 1) % static_cast<int>(streams_.size());
      if (ended_[s]) continue;
      if (!readers_[s]->Next(&f->posed.frame, status)) {
        if (!status->ok()) return false;
        ended_[s] = true;
        continue;
      }
      f->stream = s;
      return Pose(s, f, status);
    }
    return false;  // every stream ended
  }

 private:
  bool Pose(int s, LoopFrame* f, Status* status) const {
    const Capture& capture = streams_[s];
    const PosedImage* pose = capture.PoseForFrame(f->posed.frame);
    f->posed.has_pose = pose != nullptr;
    if (!pose) return true;
    f->posed.cam_from_world = pose->cam_from_world;
    f->camera = capture.CameraFor(*pose);
    if (!f->camera) {
      *status = Status::Error(project_.Resolve(specs_[s].poses) + ": image '" + pose->name +
                              "': camera " + std::to_string(pose->camera_id) + " not found");
      return false;
    }
    return true;
  }

  const Project& project_;
  const std::vector<StreamSpec> specs_;
  const std::vector<Capture>& streams_;
  std::vector<std::unique_ptr<FrameReader>> readers_;
  std::vector<bool> ended_;
  int next_ = 0;
};

// Frames read, painted and without a pose, of one stream.
struct StreamCounts {
  int frames = 0, painted = 0, without_pose = 0;
};

nlohmann::json LiveMetrics(const LiveInputs& live, int recorded) {
  const LiveFramesStats s = live.frames->stats();
  nlohmann::json j;
  j["frames_received"] = s.frames_received;
  j["frames_dropped"] = s.frames_dropped;
  j["frames_held_dropped"] = s.frames_held_dropped;
  j["frames_delivered"] = s.frames_delivered;
  j["frames_without_pose"] = s.frames_without_pose;
  j["queue_capacity"] = s.queue_capacity;
  j["queue_high_water"] = s.queue_high_water;
  j["video_reopens"] = s.video_reopens;
  j["video_clock"] = s.video_clock;
  j["end_reason"] = s.end_reason;
  j["time_offset_s"] = s.time_offset_s;
  j["offset_estimated"] = s.offset_estimated;
  if (live.feed) {
    const PoseFeedStats f = live.feed->stats();
    nlohmann::json gaps = nlohmann::json::array();
    for (const PoseFeedGap& g : f.gaps)  // NaN (no pose on that side) is written as null
      gaps.push_back({{"last_pose_before_s", g.last_pose_before_s},
                      {"first_pose_after_s", g.first_pose_after_s},
                      {"tracker_gap_s", g.tracker_gap_s()},
                      {"disconnected_s", g.disconnected_s},
                      {"attempts", g.attempts},
                      {"reconnected", g.reconnected}});
    j["pose_feed"] = {{"address", live.feed->address()},
                      {"poses", f.poses},
                      {"reconnects", f.reconnects},
                      {"disconnects", f.disconnects},
                      {"disconnected_s", f.disconnected_s},
                      {"gaps", gaps},
                      {"connected", f.connected},
                      {"seconds_since_last_pose", f.seconds_since_last_pose}};
  }
  if (!s.estimate.candidates.empty() || !s.estimate.note.empty()) {
    nlohmann::json candidates = nlohmann::json::array();
    for (const TimeOffsetCandidate& c : s.estimate.candidates)
      candidates.push_back({{"offset_s", c.offset_s},
                            {"score", c.score},
                            {"frames", c.frames_scored}});
    j["offset_estimate"] = {{"ok", s.estimate.ok},
                            {"offset_s", s.estimate.offset_s},
                            {"score", s.estimate.score},
                            {"contrast", s.estimate.contrast},
                            {"frames", s.estimate.frames},
                            {"seconds", s.estimate.seconds},
                            {"note", s.estimate.note},
                            {"candidates", candidates}};
  }
  if (!s.offset_track.empty()) {
    nlohmann::json track = nlohmann::json::array();
    for (const OffsetTrackPoint& p : s.offset_track)
      track.push_back({{"window_start_s", p.window_start_s},
                       {"time_s", p.time_s},
                       {"frames", p.frames},
                       {"offset_s", p.offset_s},
                       {"score", p.score},
                       {"current_score", p.current_score},
                       {"ok", p.ok},
                       {"applied", p.applied},
                       {"seconds", p.seconds}});
    j["offset_track"] = track;
  }
  j["recorded_frames"] = recorded;
  return j;
}

}  // namespace

int RunVerbRun(const CommandArgs& argv) {
  const ArgSpec spec = RunSpec();
  Args args;
  if (int code = ParseVerbArgs("run", argv, spec, &args); code >= 0) return code;
  const std::string project_path = args.positional[0];
  const std::string out_dir = args.Get("--out");
  const bool quiet = args.Switch("--quiet");

  Project project;
  if (Status s = LoadProject(project_path, args.All("--set"), &project); !s.ok())
    return InputError(s);
  if (args.Switch("--debug-images")) project.pipeline.debug_images = true;
  if (project.pipeline.threads > 0) cv::setNumThreads(project.pipeline.threads);

  const bool live = IsLiveProject(project);
  const std::vector<StreamSpec> specs = project.Streams();
  if (live && specs.size() > 1)
    return InputError(Status::Error(project_path +
                                    ": streams: live sources need a project with "
                                    "one stream (this one has " +
                                    std::to_string(specs.size()) + ")"));
  const std::string record_dir = args.Get("--record");
  if (!record_dir.empty() && !live)
    return InputError(Status::Error(std::string("--record: only for live sources (") + project_path +
                                    " replays files already)"));
  std::vector<Capture> captures;  // one per stream; the scene is in captures[0]
  std::unique_ptr<PaintSession> session;
  CaptureLoadOptions load_options;
  load_options.open_video = !live;  // a live video opens after the pose feed connects
  if (Status s = OpenPaintSession(project, load_options, &captures, &session); !s.ok())
    return InputError(s);
  const Scene& scene = captures[0].scene;
  LiveInputs live_inputs;
  SessionRecorder recorder;
  if (live) {
    const Project one_stream = project.ForStream(0);
    if (Status s =
            OpenLiveInputs(one_stream, captures[0], *session, !record_dir.empty(), &live_inputs);
        !s.ok())
      return InputError(s);
    if (!record_dir.empty())
      if (Status s = recorder.Start(record_dir, one_stream); !s.ok()) return InputError(s);
  }
  if (!quiet) {
    std::fprintf(
        stderr, "fresco run: %d triangles, %zu base buffers, %lld texels (%.4f m/texel)%s\n",
        scene.mesh.NumTriangles(), session->buffers().size(), session->NumSurfaceTexels(),
        session->default_texel_size_m(),
        specs.size() > 1 ? (", " + std::to_string(specs.size()) + " streams").c_str() : "");
  }

  InterruptCatcher interrupt;  // from here on, Ctrl-C stops at the next frame (interrupt.h)
  if (Status s = MakeDirectories(out_dir); !s.ok()) return InputError(s);
  // Debug images go to a staging folder that replaces DIR/stages/ only at the end.
  StagedFolder stages;
  if (project.pipeline.debug_images)
    if (Status s = stages.Open(out_dir + "/stages"); !s.ok()) return InputError(s);
  const std::string& stages_dir = stages.path();

  int total = live ? -1 : 0;  // frames of every stream; -1: unknown
  if (!live) {
    for (const Capture& capture : captures) {
      const int count = capture.video->FrameCount();
      total = total < 0 || count < 0 ? -1 : total + count;
    }
  }
  if (project.pipeline.max_frames > 0 && (total < 0 || total > project.pipeline.max_frames))
    total = project.pipeline.max_frames;
  Progress progress("painting", total, quiet);
  StageTotals totals;
  int frames = 0, frames_painted = 0, frames_without_pose = 0;
  std::vector<StreamCounts> stream_counts(specs.size());
  const auto loop_start = std::chrono::steady_clock::now();
  NextLoopFrame next;
  std::unique_ptr<InterleavedFrames> reader;
  if (live) {
    next = [&](LoopFrame* f, Status* status) {
      if (!live_inputs.frames->Next(&f->posed, status)) return false;
      f->camera = live_inputs.camera;
      return true;
    };
  } else {
    // Frames are read and decoded on other threads, one frame ahead of the painting.
    reader = std::make_unique<InterleavedFrames>(project, captures);
    next = [&](LoopFrame* f, Status* status) { return reader->Next(f, status); };
  }
  LoopFrame loop_frame;
  const Frame& frame = loop_frame.posed.frame;
  Status read_status;
  FrameReport report;
  while ((project.pipeline.max_frames <= 0 || frames < project.pipeline.max_frames) &&
         !Interrupted() && next(&loop_frame, &read_status)) {
    if (Interrupted()) break;  // arrived while the frame was read
    ++frames;
    StreamCounts& counts = stream_counts[loop_frame.stream];
    ++counts.frames;
    if (live_inputs.feed)
      if (Status s = live_inputs.feed->error(); !s.ok()) return InputError(s);
    if (!loop_frame.posed.has_pose) {
      ++frames_without_pose, ++counts.without_pose;
      progress.Update(frames);
      continue;
    }
    const Camera* camera = loop_frame.camera;
    if (Status s = CheckFrameSize(frame, *camera, project.Resolve(specs[loop_frame.stream].video));
        !s.ok())
      return InputError(s);
    if (!record_dir.empty())
      if (Status s = recorder.Add(frame, loop_frame.posed.cam_from_world); !s.ok())
        return InputError(s);
    session->PaintFrame(frame, *camera, loop_frame.posed.cam_from_world, &report);
    if (report.painted) {
      ++frames_painted, ++counts.painted;
      for (const StageReport& st : report.stages) {
        totals.ms[st.name] += st.wall_ms;
        for (const auto& [key, value] : st.metrics) {
          if (!std::isfinite(value)) continue;
          auto& [sum, count] = totals.metrics[st.name][key];
          sum += value, ++count;
        }
      }
      if (project.pipeline.debug_images)
        if (Status s = WriteStageImages(stages_dir, report); !s.ok()) return InputError(s);
    }
    char detail[64];
    std::snprintf(detail, sizeof detail, "coverage %.1f%%", 100.0 * session->Coverage());
    progress.Update(frames, detail);
  }
  if (live_inputs.frames) live_inputs.frames->Stop();
  if (!read_status.ok()) return InputError(read_status);
  if (Interrupted()) {
    progress.Clear();
    std::fprintf(stderr,
                 "fresco run: interrupted by %s after %d frame%s; nothing written to %s (outputs "
                 "of earlier runs there are kept)\n",
                 InterruptSignalName().c_str(), frames, frames == 1 ? "" : "s", out_dir.c_str());
    return InterruptExitCode();
  }
  if (live_inputs.feed)
    if (Status s = live_inputs.feed->error(); !s.ok()) return InputError(s);
  if (!record_dir.empty()) {
    const std::vector<TimedPose> tracker =
        live_inputs.feed ? live_inputs.feed->AllPoses()
                         : std::vector<TimedPose>(live_inputs.track->samples().begin(),
                                                  live_inputs.track->samples().end());
    if (Status s = recorder.Finish(tracker); !s.ok()) return InputError(s);
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - loop_start).count();
  progress.Finish();

  // Outputs: written into a staging folder inside DIR, then moved into DIR with metrics.json
  // last; a failure before that leaves DIR as it was (all or nothing).
  StagedFolder outputs;
  if (Status s = outputs.Open(out_dir + "/.outputs"); !s.ok()) {
    std::cerr << "error: " << s.message() << "\n";
    return kExitFailure;
  }
  if (Status s = SaveGltfScene(session->PaintedScene(), outputs.path() + "/painted.gltf"); !s.ok()) {
    std::cerr << "error: " << s.message() << "\n";
    return kExitFailure;
  }
  nlohmann::json metrics;
  metrics["frames"] = frames;
  metrics["frames_painted"] = frames_painted;
  metrics["frames_without_pose"] = frames_without_pose;
  metrics["seconds"] = seconds;
  metrics["fps"] = seconds > 0 ? frames / seconds : 0.0;
  metrics["paint_fps"] = seconds > 0 ? frames_painted / seconds : 0.0;
  nlohmann::json stage_ms = nlohmann::json::object();
  for (const auto& [name, ms] : totals.ms)
    stage_ms[name] = frames_painted > 0 ? ms / frames_painted : 0.0;
  metrics["stage_ms"] = stage_ms;
  // Each stage's metrics, averaged over the frames where they were defined.
  nlohmann::json stage_metrics = nlohmann::json::object();
  for (const auto& [stage, by_key] : totals.metrics)
    for (const auto& [key, sum_count] : by_key)
      stage_metrics[stage][key] = sum_count.first / sum_count.second;
  metrics["stage_metrics"] = stage_metrics;
  metrics["texels"] = session->NumSurfaceTexels();
  metrics["texels_painted"] = session->NumPaintedSurfaceTexels();
  metrics["coverage"] = session->Coverage();
  metrics["base_buffers"] = session->buffers().size();
  metrics["texel_size_m"] = session->default_texel_size_m();
  metrics["groups_split_for_folds"] = session->folds_split();
  const ChartStretch stretch = MeasureChartStretch(scene.mesh, session->grouping());
  metrics["charts"] = {{"count", session->buffers().size()},
                       {"max_stretch", stretch.max},
                       {"mean_stretch", stretch.mean}};
  metrics["triangles"] = scene.mesh.NumTriangles();
  // Per stream, in the project's order: its video and what came of its frames.
  nlohmann::json streams = nlohmann::json::array();
  for (size_t i = 0; i < specs.size(); ++i)
    streams.push_back({{"video", specs[i].video},
                       {"frames", stream_counts[i].frames},
                       {"frames_painted", stream_counts[i].painted},
                       {"frames_without_pose", stream_counts[i].without_pose}});
  metrics["streams"] = streams;
  nlohmann::json buffers = nlohmann::json::array();
  for (size_t b = 0; b < session->buffers().size(); ++b) {
    const BaseBuffer& buf = session->buffers()[b];
    buffers.push_back({{"id", b},
                       {"triangles", buf.triangles.size()},
                       {"width", buf.width},
                       {"height", buf.height},
                       {"texel_size_m", buf.texel_size_m},
                       {"texels", buf.num_surface_texels},
                       {"painted", session->painted()[b].painted_surface_texels}});
  }
  metrics["buffers"] = buffers;
  const TextureAtlas& atlas = session->atlas();
  nlohmann::json pages = nlohmann::json::array();
  for (const cv::Size& page : atlas.pages) pages.push_back({page.width, page.height});
  metrics["atlas"] = {{"pages", atlas.pages.size()},
                      {"page_sizes", pages},
                      {"occupancy", atlas.Occupancy()},
                      {"padding_texels", atlas.padding}};
  if (live) metrics["live"] = LiveMetrics(live_inputs, recorder.frames());
  if (Status s = WriteFileAtomic(outputs.path() + "/metrics.json", metrics.dump(2) + "\n");
      !s.ok()) {
    std::cerr << "error: " << s.message() << "\n";
    return kExitFailure;
  }
  if (Status s = MoveFilesInto(outputs.path(), out_dir, {"metrics.json"}); !s.ok()) {
    std::cerr << "error: " << s.message() << "\n";
    return kExitFailure;
  }
  if (project.pipeline.debug_images) {
    if (Status s = stages.Commit(); !s.ok()) {
      std::cerr << "error: " << s.message() << "\n";
      return kExitFailure;
    }
  }
  if (Interrupted()) {  // while the outputs were written: they were finished first
    std::fprintf(stderr, "fresco run: interrupted by %s while writing; finished writing %s first\n",
                 InterruptSignalName().c_str(), out_dir.c_str());
    return InterruptExitCode();
  }
  if (!quiet) {
    std::fprintf(stderr,
                 "fresco run: %d frames (%d painted) in %.2fs = %.1f fps; coverage %.1f%% of %lld "
                 "texels in %zu buffers -> %s\n",
                 frames, frames_painted, seconds, metrics["fps"].get<double>(),
                 100.0 * session->Coverage(), session->NumSurfaceTexels(),
                 session->buffers().size(), out_dir.c_str());
  }
  return kExitOk;
}

}  // namespace fresco
