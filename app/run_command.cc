// fresco run PROJECT.json --out DIR [--set KEY=VALUE ...]: replays a project headless,
// paints every frame, writes DIR/painted.gltf, DIR/metrics.json and (opt-in) DIR/stages/.
#include <sys/resource.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>

#include "app/commands.h"
#include "app/interrupt.h"
#include "app/progress.h"
#include "pipeline/core/atomic_file.h"
#include "pipeline/core/capture.h"
#include "pipeline/core/image_io.h"
#include "pipeline/core/project.h"
#include "pipeline/live/live_input.h"
#include "pipeline/paint/charts.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/run/live_status.h"
#include "pipeline/run/paint_job.h"
#include "pipeline/run/paint_run.h"
#include "pipeline/run/prepass_file.h"
#include "pipeline/run/shard.h"

namespace fresco {
namespace {

ArgSpec RunSpec() {
  ArgSpec spec;
  spec.usage =
      "fresco run PROJECT.json --out DIR [--set KEY=VALUE ...] [--debug-images] [--quiet]\n"
      "       [--record DIR] [--shard I/N] [--prepass FILE [--prepass-only]]";
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
      "                    DIR/frames/, DIR/poses.txt, DIR/project.json\n"
      "  --shard I/N       paint only shard I (0..N-1) of N: its charts (balanced by texels),\n"
      "                    reading only the frames that see them; DIR holds a part that\n"
      "                    `fresco merge` joins with the others into exactly this run's\n"
      "                    outputs (docs/guide/slurm.md; captures from files)\n"
      "  --prepass FILE    the whole-capture pre-pass (the joint pose check, the movers found\n"
      "                    across views, the decisions they take) and the charts' layout read\n"
      "                    from FILE; when FILE does not exist, run and written to it: the\n"
      "                    shards of one project run it once, and a shard that reads it\n"
      "                    builds only its own charts (FILE is for this project and these\n"
      "                    settings only)\n"
      "  --prepass-only    write the --prepass FILE and stop, painting nothing (no --out)\n\n"
      "Live sources (docs/guide/live.md): `video` may be device:N or a stream URL\n"
      "(udp://127.0.0.1:5000, rtsp://..., http://...), `poses` a feed of TUM lines\n"
      "(tcp://HOST:PORT, udp://HOST:PORT, fifo://PATH) or a TUM file; frames match poses\n"
      "by time (+ time_offset_s, estimated with live.estimate_offset); the run ends when\n"
      "the video ends (its stream ends, or no frame within live.read_timeout_s; the\n"
      "\"live\" object in metrics.json says which in end_reason).\n\n"
      "Several streams (\"fresco\": 2, `streams`): their frames paint one model, interleaved\n"
      "by frame index (frame 0 of each stream, then frame 1 of each, ...); a stream that\n"
      "ends early leaves the others going on. pipeline.max_frames counts frames of all\n"
      "streams. When a stream is live, frames are painted as they arrive, the streams\n"
      "taken in turn (none starves another), and metrics.json has a \"live\" object per\n"
      "live stream in \"streams\". --record needs a project with one stream.";
  spec.min_positional = spec.max_positional = 1;
  spec.options = {"--out", "--record", "--shard", "--prepass"};
  spec.repeatable = {"--set"};
  spec.switches = {"--debug-images", "--quiet", "--prepass-only"};
  return spec;
}

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

// The process's peak resident set so far, MB.
double PeakRssMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // KB on Linux
}

nlohmann::json LiveMetrics(const LiveStatus& live) {
  const LiveFramesStats& s = live.frames;
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
  if (live.pose_feed) {
    const PoseFeedStats& f = live.feed;
    nlohmann::json gaps = nlohmann::json::array();
    for (const PoseFeedGap& g : f.gaps)  // NaN (no pose on that side) is written as null
      gaps.push_back({{"last_pose_before_s", g.last_pose_before_s},
                      {"first_pose_after_s", g.first_pose_after_s},
                      {"tracker_gap_s", g.tracker_gap_s()},
                      {"disconnected_s", g.disconnected_s},
                      {"attempts", g.attempts},
                      {"reconnected", g.reconnected}});
    j["pose_feed"] = {{"address", live.pose_feed_address},
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
      candidates.push_back(
          {{"offset_s", c.offset_s}, {"score", c.score}, {"frames", c.frames_scored}});
    j["offset_estimate"] = {{"ok", s.estimate.ok},         {"offset_s", s.estimate.offset_s},
                            {"score", s.estimate.score},   {"contrast", s.estimate.contrast},
                            {"frames", s.estimate.frames}, {"seconds", s.estimate.seconds},
                            {"note", s.estimate.note},     {"candidates", candidates}};
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
  j["recorded_frames"] = live.recorded_frames;
  return j;
}

// What metrics.json holds (CONTRACT.md): the run's statistics, the session's buffers and
// atlas, and for live projects the sources' state.
nlohmann::json RunMetrics(const Project& project, const PaintJob& job, const PaintRunStats& stats,
                          const Status& end, const LiveRecording& recording) {
  const PaintSession* session = job.session.get();
  const Scene& scene = job.scene();
  const std::vector<StreamSpec> specs = project.Streams();
  nlohmann::json metrics;
  metrics["frames"] = stats.frames;
  metrics["frames_painted"] = stats.frames_painted;
  metrics["frames_without_pose"] = stats.frames_without_pose;
  if (stats.frames_skipped > 0) metrics["frames_skipped"] = stats.frames_skipped;
  metrics["seconds"] = stats.seconds;
  metrics["fps"] = stats.Fps();
  metrics["paint_fps"] = stats.PaintFps();
  metrics["stage_ms"] = nlohmann::json::object();
  for (const auto& [name, ms] : stats.MeanStageMs()) metrics["stage_ms"][name] = ms;
  // Each stage's metrics, averaged over the frames where they were defined.
  metrics["stage_metrics"] = nlohmann::json::object();
  for (const auto& [stage, by_key] : stats.MeanStageMetrics())
    for (const auto& [key, mean] : by_key) metrics["stage_metrics"][stage][key] = mean;
  // What the `auto` modes decided, with their evidence (null for a mode not auto).
  metrics["auto"] = nlohmann::json::parse(AutoDecisionsJson(session->auto_decisions()));
  if (job.joint_poses) {  // pipeline.refine.joint: the poses adjusted before painting
    metrics["joint_poses"] = PoseAdjustSummaryJson(*job.joint_poses);
  }
  if (job.mover_masks) {  // background.mode auto: movers found across views before painting
    const MoverMaskResult& m = *job.mover_masks;
    metrics["movers_across_views"] = {{"not_run", m.not_run},
                                      {"pixels_judged", m.judged},
                                      {"pixels_masked", m.flagged},
                                      {"fraction", m.fraction()},
                                      {"pixels_in_regions", m.compact},
                                      {"fraction_in_regions", m.compact_fraction()},
                                      {"frames_judged", m.frames_judged},
                                      {"seconds", m.seconds}};
  }
  metrics["texels"] = session->NumSurfaceTexels();
  metrics["texels_painted"] = session->NumPaintedSurfaceTexels();
  metrics["coverage"] = session->Coverage();
  metrics["base_buffers"] = session->buffers().size();
  metrics["texel_size_m"] = session->default_texel_size_m();
  metrics["groups_split_for_folds"] = session->folds_split();
  const ChartStretch stretch = MeasureBufferStretch(scene.mesh, session->buffers());
  metrics["charts"] = {{"count", session->buffers().size()},
                       {"max_stretch", stretch.max},
                       {"mean_stretch", stretch.mean}};
  metrics["triangles"] = scene.mesh.NumTriangles();
  // Per stream, in the project's order: its video, what came of its frames and the fraction
  // of its samples its background model masked (null when the background stage saw none).
  nlohmann::json streams = nlohmann::json::array();
  for (size_t i = 0; i < specs.size(); ++i) {
    const StreamRunStats& stream = stats.streams[i];
    const double masked = stream.MaskedFraction();
    streams.push_back(
        {{"video", specs[i].video},
         {"frames", stream.frames},
         {"frames_painted", stream.painted},
         {"frames_without_pose", stream.without_pose},
         {"frames_skipped", stream.skipped},
         {"masked_fraction", std::isnan(masked) ? nlohmann::json() : nlohmann::json(masked)}});
  }
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
  // Live streams: each its sources' state, in "streams"; the first also as "live" (what a
  // project with one stream has always had).
  for (size_t i = 0; i < job.live_inputs.size(); ++i) {
    if (!job.live_inputs[i].frames) continue;
    LiveStatus status = LiveWatch().Read(project.ForStream(static_cast<int>(i)),
                                         job.live_inputs[i], true, end, -1);
    recording.Describe(&status);
    const nlohmann::json live = LiveMetrics(status);
    metrics["streams"][i]["live"] = live;
    if (!metrics.contains("live")) metrics["live"] = live;
  }
  return metrics;
}

// The process's CPU time so far (user + system), seconds.
double CpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
         1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

// --shard I/N: metrics.json's "shard" (CONTRACT.md: index, count), with what `fresco merge`
// needs: the project and settings it was painted with, the buffers it painted and where they
// lie in the atlas pages (with their padding), and what it cost.
nlohmann::json ShardMetrics(const Project& project, const PaintJob& job, const ShardSpec& shard,
                            const PaintRunStats& stats) {
  const PaintSession& session = *job.session;
  const TextureAtlas& atlas = session.atlas();
  nlohmann::json buffers = nlohmann::json::array(), rects = nlohmann::json::array();
  long long texels = 0, painted = 0;
  int built = 0;  // buffers with texels: its own, or every one (PaintSession::SetOwnBuffers)
  for (size_t b = 0; b < job.buffer_shard.size(); ++b) {
    built += session.BufferBuilt(b);
    if (job.buffer_shard[b] != shard.index) continue;
    const BaseBuffer& buffer = session.buffers()[b];
    buffers.push_back(b);
    texels += buffer.num_surface_texels;
    painted += session.painted()[b].painted_surface_texels;
    const int page = atlas.placements[b].page;
    if (page < 0) continue;
    const cv::Rect padded = PaddedPlacement(atlas, b, cv::Size(buffer.width, buffer.height));
    rects.push_back({page, padded.x, padded.y, padded.width, padded.height});
  }
  return {{"index", shard.index},
          {"count", shard.count},
          {"project", project.file_path},
          {"settings_hash", SettingsHash(project)},
          {"layout", LayoutDigest(job.scene(), session.buffers(), atlas)},
          {"buffers", buffers},
          {"page_rects", rects},
          {"texels", texels},
          {"texels_painted", painted},
          {"frames_skipped", stats.frames_skipped},
          {"frames_painted_whole", session.frames_painted_whole()},
          {"buffers_built", built},
          {"work",
           {{"texels", job.shard_work.texels},
            {"texel_frames", job.shard_work.texel_frames},
            {"frames", job.shard_work.frames},
            {"window_frames", job.shard_work.window_frames},
            {"estimated_cpu_seconds", job.shard_estimated_s}}},
          {"cpu_seconds", CpuSeconds()}};
}

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The run's wall time as a user waits for it, from the verb's start to the outputs written
// (metrics.json is written last, just after): opening (loading, the pre-pass step by step),
// painting (decoding included), writing; and the frames read per second of it ("fps" counts
// the painting loop only).
nlohmann::json WallJson(const PaintJob& job, const PaintRunStats& stats, double total_s,
                        double write_s) {
  const PaintJob::OpenSeconds& o = job.open_seconds;
  return {{"seconds", total_s},
          {"frames_per_second", total_s > 0 ? stats.frames / total_s : 0.0},
          {"open_seconds",
           {{"total", o.total},
            {"load", o.load},
            {"cameras", o.cameras},
            {"prepass_read", o.read},
            {"prepass_joint", o.joint},
            {"prepass_movers", o.movers},
            {"prepass_file", o.prepass_file},
            {"connect", o.connect}}},
          {"paint_seconds", stats.seconds},
          {"write_seconds", write_s},
          {"other_seconds", std::max(0.0, total_s - o.total - stats.seconds - write_s)}};
}

// Writes DIR/painted.gltf (+ .bin, PNGs; a shard but the first, its PNGs only) and
// DIR/metrics.json: into a staging folder inside DIR first, then moved into DIR with metrics.json
// last; a failure before that leaves DIR as it was (all or nothing). Errors are not bad input (exit
// 1).
Status WriteRunOutputs(const std::string& out_dir, const PaintJob& job, int shard_index,
                       const PaintRunStats& stats, Clock::time_point start,
                       nlohmann::json metrics) {
  const auto writing = Clock::now();
  StagedFolder outputs;
  FRESCO_RETURN_IF_ERROR(outputs.Open(out_dir + "/.outputs"));
  // A shard's part: its pages hold only its own buffers' placements (fresco merge); the glTF
  // and its .bin, the same in every part (the layout is), only in shard 0's.
  const std::string gltf = outputs.path() + "/painted.gltf";
  if (job.buffer_shard.empty())
    FRESCO_RETURN_IF_ERROR(SaveGltfScene(job.session->PaintedScene(), gltf));
  else if (shard_index == 0)
    FRESCO_RETURN_IF_ERROR(SaveGltfScene(job.session->PaintedSceneOfOwnBuffers(), gltf));
  else
    FRESCO_RETURN_IF_ERROR(SaveGltfTextures(job.session->PaintedSceneOfOwnBuffers(false), gltf));
  metrics["wall"] = WallJson(job, stats, SecondsSince(start), SecondsSince(writing));
  FRESCO_RETURN_IF_ERROR(WriteFileAtomic(outputs.path() + "/metrics.json", metrics.dump(2) + "\n"));
  return MoveFilesInto(outputs.path(), out_dir, {"metrics.json"});
}

// The frames the run will read (for its progress): every stream's, at most max_frames; -1
// when unknown (live).
int FramesToRead(const PaintJob& job, const Project& project) {
  const int total = job.source->FrameCount();
  const int max_frames = project.pipeline.max_frames;
  return max_frames > 0 && (total < 0 || total > max_frames) ? max_frames : total;
}

// The last line of a run (unless --quiet).
void PrintRunSummary(const PaintRunStats& stats, const PaintSession& session,
                     const std::string& out_dir, double wall_s) {
  // Refinement turned down by the pose check, and a model the frames held out turned off after
  // the line before painting said on, say so (the other decisions are in metrics.json).
  const AutoDecisions decided = session.auto_decisions();
  if (decided.refine.basis == "held_out_poses")
    std::fprintf(stderr, "fresco run: refinement %s\n", decided.refine.Describe().c_str());
  if (decided.background.basis == "held_out_without_model")
    std::fprintf(stderr, "fresco run: background %s\n", decided.background.Describe().c_str());
  std::fprintf(stderr,
               "fresco run: %d frames (%d painted) in %.2fs = %.1f fps; %.2fs end to end = %.1f "
               "fps; coverage %.1f%% of %lld texels in %zu buffers -> %s\n",
               stats.frames, stats.frames_painted, stats.seconds, stats.Fps(), wall_s,
               wall_s > 0 ? stats.frames / wall_s : 0.0, 100.0 * session.Coverage(),
               session.NumSurfaceTexels(), session.buffers().size(), out_dir.c_str());
}

// --record DIR: only for a live project with one stream.
Status CheckRecording(const Project& project, const std::string& project_path,
                      const std::string& record_dir) {
  if (record_dir.empty()) return Status::Ok();
  if (!IsLiveProject(project))
    return Status::Error(std::string("--record: only for live sources (") + project_path +
                         " replays files already)");
  const size_t streams = project.Streams().size();
  if (streams > 1)
    return Status::Error(project_path +
                         ": streams: --record records a project with one stream (this one has " +
                         std::to_string(streams) + ")");
  return Status::Ok();
}

// What the job set up and what its pre-pass did, on stderr (before painting).
void PrintJobSummary(const PaintJob& job, size_t streams) {
  const PaintSession* session = job.session.get();
  const Scene& scene = job.scene();
  std::fprintf(
      stderr, "fresco run: %d triangles, %zu base buffers, %lld texels (%.4f m/texel)%s\n",
      scene.mesh.NumTriangles(), session->buffers().size(), session->NumSurfaceTexels(),
      session->default_texel_size_m(),
      streams > 1 ? (", " + std::to_string(streams) + " streams").c_str() : "");
  if (job.joint_poses && !job.joint_poses->not_run.empty()) {
    std::fprintf(stderr, "fresco run: poses not adjusted together: %s\n",
                 job.joint_poses->not_run.c_str());
  } else if (job.joint_poses) {
    const PoseAdjustResult& a = *job.joint_poses;
    const int frames = static_cast<int>(a.cam_from_local.size());
    const std::string on = a.decided_on_frames < frames
                               ? " on the first " + std::to_string(a.decided_on_frames) + " frames"
                               : "";
    std::fprintf(stderr,
                 "fresco run: poses adjusted together%s: a frame left out against the corrected "
                 "ones agrees %.3f -> %.3f px (%d tracks, %.1f s): %s",
                 on.c_str(), a.check_before_px, a.check_one_end_px, a.check_matches,
                 a.check_seconds, a.applied ? "applied" : "not applied");
    const double needed = PoseAdjustOptions().check_min_improvement;
    if (!a.applied && a.check_one_end_px > 0 && a.check_before_px >= needed * a.check_one_end_px)
      std::fprintf(stderr, " (no tracks to adjust every pose from)\n");
    else if (!a.applied)
      std::fprintf(stderr, " (not %.1f times better)\n", needed);
    if (a.applied)
      std::fprintf(stderr, "; %d tracks, RMS %.3f -> %.3f px, median correction %.3f deg, %.1f mm (%.1f s)\n",
                   a.inliers, a.rms_before_px, a.rms_after_px, a.median_rotation_deg,
                   1000 * a.median_translation_m, a.seconds);
  }
  if (job.mover_masks && !job.mover_masks->not_run.empty())
    std::fprintf(stderr, "fresco run: background decided frame by frame: %s\n",
                 job.mover_masks->not_run.c_str());
  else if (job.mover_masks)
    std::fprintf(stderr, "fresco run: background %s (%.1f s)\n",
                 session->auto_decisions().background.Describe().c_str(),
                 job.mover_masks->seconds);
}

}  // namespace

int RunVerbRun(const CommandArgs& argv) {
  const ArgSpec spec = RunSpec();
  Args args;
  if (int code = ParseVerbArgs("run", argv, spec, &args); code >= 0) return code;
  const auto start = Clock::now();  // the wall time a user waits for starts here
  const std::string project_path = args.positional[0];
  const std::string out_dir = args.Get("--out");
  const bool quiet = args.Switch("--quiet");
  const std::string prepass_file = args.Get("--prepass");
  const bool prepass_only = args.Switch("--prepass-only");
  if (prepass_only && prepass_file.empty())
    return Fail(Status::Error("--prepass-only: needs --prepass FILE (the file to write)"));
  if (!prepass_only && !args.Has("--out")) return UsageError("run", spec, "missing --out");

  Project project;
  if (Status s = LoadProject(project_path, args.All("--set"), &project); !s.ok()) return Fail(s);
  if (args.Switch("--debug-images")) project.pipeline.debug_images = true;
  if (project.pipeline.threads > 0) cv::setNumThreads(project.pipeline.threads);

  const std::vector<StreamSpec> specs = project.Streams();
  const std::string record_dir = args.Get("--record");
  ShardSpec shard;
  if (args.Has("--shard"))
    if (Status s = ParseShardSpec(args.Get("--shard"), "--shard", &shard); !s.ok()) return Fail(s);
  if (shard.sharded() && !record_dir.empty())
    return Fail(Status::Error("--shard: not with --record (a shard paints a capture from files)"));
  if (Status s = CheckRecording(project, project_path, record_dir); !s.ok()) return Fail(s);
  PaintJobOptions job_options;
  job_options.keep_tracker_poses = !record_dir.empty();
  job_options.shard = shard;
  job_options.prepass_file = prepass_file;
  job_options.prepass_only = prepass_only;
  job_options.joint_progress = ProgressLines("adjusting poses", quiet);
  job_options.movers_progress = ProgressLines("finding movers, pass", quiet);
  std::unique_ptr<PaintJob> job;
  if (Status s = OpenPaintJob(project, job_options, &job); !s.ok()) return Fail(s);
  if (prepass_only) {
    if (!quiet) {
      PrintJobSummary(*job, specs.size());
      std::fprintf(stderr, "fresco run: whole-capture pre-pass -> %s\n", prepass_file.c_str());
    }
    return kExitOk;
  }
  const double setup_peak_rss_mb = PeakRssMb();
  PaintSession* session = job->session.get();
  LiveRecording recording;
  if (!record_dir.empty())
    if (Status s = recording.Start(record_dir, project.ForStream(0), true); !s.ok())
      return Fail(s);
  if (!quiet) PrintJobSummary(*job, specs.size());

  InterruptCatcher interrupt;  // from here on, Ctrl-C stops at the next frame (interrupt.h)
  if (Status s = MakeDirectories(out_dir); !s.ok()) return Fail(s);
  // Debug images go to a staging folder that replaces DIR/stages/ only at the end.
  StagedFolder stages;
  if (project.pipeline.debug_images)
    if (Status s = stages.Open(out_dir + "/stages"); !s.ok()) return Fail(s);
  const std::string& stages_dir = stages.path();

  Progress progress("painting", FramesToRead(*job, project), quiet);
  PaintRunOptions run_options;
  run_options.max_frames = project.pipeline.max_frames;
  PaintRun run(session, job->source.get(), run_options);
  PaintRunHooks hooks;
  hooks.stop = [] { return Interrupted(); };
  hooks.before_paint = [&](const RunFrame& f) {
    return recording.Add(f.posed);
  };
  hooks.after_frame = [&](const RunFrame&, const FrameReport* report) {
    if (report && project.pipeline.debug_images)
      FRESCO_RETURN_IF_ERROR(WriteStageImages(stages_dir, *report));
    char detail[64];
    std::snprintf(detail, sizeof detail, "coverage %.1f%%", 100.0 * session->Coverage());
    progress.Update(run.stats().frames, detail);
    return Status::Ok();
  };
  if (Status s = RunToEnd(&run, hooks); !s.ok()) return Fail(s);
  const PaintRunStats& stats = run.stats();
  const int frames = stats.frames;
  if (Interrupted()) {
    progress.Clear();
    std::fprintf(stderr,
                 "fresco run: interrupted by %s after %d frame%s; nothing written to %s (outputs "
                 "of earlier runs there are kept)\n",
                 InterruptSignalName().c_str(), frames, frames == 1 ? "" : "s", out_dir.c_str());
    return InterruptExitCode();
  }
  if (recording.active()) {
    std::string recorded;
    if (Status s = recording.Finish(job->live_inputs[0], &recorded); !s.ok()) return Fail(s);
  }
  progress.Finish();

  nlohmann::json metrics = RunMetrics(project, *job, stats, run.status(), recording);
  // Where the memory goes: the process's peak after set-up (mesh, charts, buffers) and after
  // painting; writing the outputs may raise it further (not in here: measure the process).
  metrics["peak_rss_mb"] = {{"setup", setup_peak_rss_mb}, {"painting", PeakRssMb()}};
  if (shard.sharded()) metrics["shard"] = ShardMetrics(project, *job, shard, stats);
  if (Status s = WriteRunOutputs(out_dir, *job, shard.index, stats, start, std::move(metrics));
      !s.ok()) {
    return Fail(s);
  }
  if (project.pipeline.debug_images) {
    if (Status s = stages.Commit(); !s.ok()) {
      return Fail(s);
    }
  }
  if (Interrupted()) {  // while the outputs were written: they were finished first
    std::fprintf(stderr, "fresco run: interrupted by %s while writing; finished writing %s first\n",
                 InterruptSignalName().c_str(), out_dir.c_str());
    return InterruptExitCode();
  }
  if (!quiet) PrintRunSummary(stats, *session, out_dir, SecondsSince(start));
  return kExitOk;
}

}  // namespace fresco
