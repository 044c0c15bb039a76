#include "pipeline/run/paint_job.h"

#include <malloc.h>
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "pipeline/paint/joint_pose_adjustment.h"
#include "pipeline/paint/mover_masks.h"
#include "pipeline/paint/open_project.h"
#include "pipeline/render/renderer.h"
#include "pipeline/run/file_frame_source.h"
#include "pipeline/run/live_frame_source.h"
#include "pipeline/run/merged_frame_source.h"
#include "pipeline/run/offset_estimator.h"
#include "pipeline/run/prepass_file.h"

namespace fresco {

namespace {

// The most the pre-pass keeps of the frames it decoded, for painting to take (bytes; 98
// frames of 640 x 480 are 90 MB).
constexpr size_t kKeepDecodedBytes = size_t{256} << 20;
// The most the movers' search keeps of the frames' depth at full size, for painting to take
// (mover_masks.h, full_size_depth; 98 frames of 640 x 480 are 120 MB): when the whole
// capture's do not fit, none is kept and frames are rasterized at the reduced size.
constexpr size_t kKeepDepthBytes = size_t{256} << 20;

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// What the whole-capture pre-pass found that goes into the captures and the session once it
// is built (ApplyWholeCapturePrepass): the pre-pass runs while the session is built.
struct PrepassFound {
  std::vector<std::pair<std::pair<int, int>, Rigid3d>> poses;  // (stream, pose index), adjusted
  std::vector<std::vector<cv::Mat>> movers;  // per stream, per pose (background.across_views)
  bool read = false;                         // the frames were read: the videos open again
};

// The movers found across views (each stream's frames compared with that stream's frames
// near them), which decide the background; the masks kept for the captures when the model
// joins them. `small[k]`, `frames[k]`, `cam_from_local[k]`: frame k of the pre-pass, at
// stream and pose index `where[k]`.
Status FindMoversAcrossViews(const Project& project, const MoverMaskOptions& mover_options,
                             const std::vector<cv::Mat>& small,
                             const std::vector<PoseAdjustFrame>& frames,
                             const std::vector<Rigid3d>& cam_from_local,
                             const std::vector<std::pair<int, int>>& where, PaintJob* j,
                             PrepassFound* found_for_captures) {
  // Each stream's frames are compared with that stream's frames near them.
  MoverMaskResult all;
  for (size_t s = 0; s < j->captures.size(); ++s) {
    std::vector<MoverMaskFrame> stream_frames;
    std::vector<int> pose_index;
    for (size_t k = 0; k < where.size(); ++k) {
      if (where[k].first != static_cast<int>(s)) continue;
      MoverMaskFrame frame;
      frame.bgr = small[k];
      frame.camera = frames[k].camera;
      frame.cam_from_local = cam_from_local[k];
      stream_frames.push_back(frame);
      pose_index.push_back(where[k].second);
    }
    MoverMaskResult found;
    FRESCO_RETURN_IF_ERROR(FindMoverMasks(j->scene().mesh, stream_frames, mover_options, &found));
    for (size_t k = 0; k < found.depths.size() && j->decoded; ++k)
      if (!found.depths[k].empty())
        j->decoded->KeepDepth(static_cast<int>(s), pose_index[k], std::move(found.depths[k]),
                              stream_frames[k].cam_from_local);
    all.judged += found.judged, all.flagged += found.flagged, all.compact += found.compact;
    all.frames_judged += found.frames_judged;
    all.seconds += found.seconds;
    if (project.pipeline.background.across_views) {
      std::vector<cv::Mat>& movers = found_for_captures->movers[s];
      movers.resize(j->captures[s].poses.size());
      for (size_t k = 0; k < pose_index.size(); ++k) movers[pose_index[k]] = found.Packed(k);
    }
  }
  j->mover_masks = all;
  j->prepass.background_across_views = {all.compact_fraction(), all.frames_judged};
  return Status::Ok();
}

// What needs the whole capture before painting: every frame is read once (kept grey for the
// joint adjustment of the poses, refine.joint: joint_pose_adjustment.h; small and in colour
// for the movers found across views that background.mode auto decides on and, with
// background.across_views, the model's foreground joins: mover_masks.h), the poses are
// adjusted and written into the captures, the background decided, each frame's movers kept
// with its capture; the videos open again for painting. It needs the scene and the captures,
// not the session: what goes into them waits in `found` (ApplyWholeCapturePrepass), and it
// may run while the session is built.
Status RunWholeCapturePrepass(const Project& project, const PaintJobOptions& options, PaintJob* j,
                              PrepassFound* found) {
  j->prepass.ran = true;
  const bool joint = project.pipeline.refine.joint;
  const bool movers = NeedsMoversAcrossViews(project.pipeline.background);
  PoseAdjustOptions adjust_options;
  adjust_options.progress = options.joint_progress;
  MoverMaskOptions mover_options = MoverMaskOptionsFor(project.pipeline.background);
  mover_options.progress = options.movers_progress;
  // A capture too long to hold is not read for it (the frames with poses count).
  size_t posed = 0;
  for (const Capture& capture : j->captures) posed += capture.poses.size();
  const int limit = project.pipeline.max_frames > 0
                        ? std::min<int>(static_cast<int>(posed), project.pipeline.max_frames)
                        : static_cast<int>(posed);
  if (std::string why = TooManyFramesToAdjust(limit, adjust_options); !why.empty()) {
    if (joint) {
      j->joint_poses = PoseAdjustResult();
      j->joint_poses->not_run = why;
    }
    if (movers) {
      j->mover_masks = MoverMaskResult();
      j->mover_masks->not_run = why;
    }
    return Status::Ok();
  }
  std::vector<const Capture*> streams;
  for (const Capture& capture : j->captures) streams.push_back(&capture);
  found->read = true;
  found->movers.resize(j->captures.size());
  std::vector<PoseAdjustFrame> frames;
  std::vector<cv::Mat> small;              // colour, at the movers' size
  std::vector<std::pair<int, int>> where;  // stream, pose index
  PaintJob::OpenSeconds& seconds = j->open_seconds;
  auto step = std::chrono::steady_clock::now();
  {
    FileFrameSource source(project, streams, nullptr, /*read_frames_without_pose=*/false);
    j->decoded = std::make_shared<DecodedFrames>(streams.size());
    std::vector<bool> folder;  // a video file's frames cannot be passed over unread
    for (const Capture* capture : streams) folder.push_back(!capture->video->FrameNames().empty());
    SourcedFrame f;
    Status status;
    int to_read = source.FrameCount();
    if (project.pipeline.max_frames > 0 && to_read >= 0)
      to_read = std::min(to_read, project.pipeline.max_frames);
    for (int read = 0; (project.pipeline.max_frames <= 0 || read < project.pipeline.max_frames) &&
                       source.Next(&f, &status) == FrameRead::kFrame;
         ++read) {
      if (options.stop && options.stop()) return Status::Error(project.file_path + ": interrupted");
      if (options.read_progress) options.read_progress(read + 1, to_read, f.posed.frame.name);
      const int every = options.joint_holdout_every;
      if (read == options.joint_holdout_counter || (every > 0 && read % every == every / 2))
        continue;
      if (!f.posed.has_pose || !f.camera || f.pose_index < 0) continue;
      const cv::Mat& bgr = f.posed.frame.bgr;
      if (bgr.size() != cv::Size(f.camera->width, f.camera->height)) continue;
      PoseAdjustFrame frame;
      if (joint) cv::cvtColor(bgr, frame.bgr, cv::COLOR_BGR2GRAY);
      frame.camera = f.camera;
      frame.cam_from_local = CamFromLocal(j->scene(), f.posed.cam_from_world);
      frames.push_back(frame);
      if (movers) {
        small.emplace_back();
        cv::resize(bgr, small.back(), MoverMaskSize(*f.camera, mover_options), 0, 0,
                   cv::INTER_AREA);
      }
      where.emplace_back(f.stream, f.pose_index);
      // Painting takes it instead of decoding it again, while the frames kept fit.
      if (folder[f.stream] &&
          j->decoded->bytes() + bgr.total() * bgr.elemSize() <= kKeepDecodedBytes)
        j->decoded->Keep(f.stream, f.pose_index, bgr);
    }
    FRESCO_RETURN_IF_ERROR(status);
  }
  seconds.read = SecondsSince(step);
  step = std::chrono::steady_clock::now();
  std::vector<Rigid3d> cam_from_local;
  for (const PoseAdjustFrame& frame : frames) cam_from_local.push_back(frame.cam_from_local);
  if (joint) {
    PoseAdjustResult adjusted;
    FRESCO_RETURN_IF_ERROR(AdjustPosesOnMesh(j->scene().mesh, frames, adjust_options, &adjusted));
    j->joint_poses = adjusted;
    // Where the check found corrections that frames left out do not agree better with,
    // refinement (a correction of the same kind, per frame) is not switched on either.
    if (adjusted.not_run.empty() && adjust_options.check_min_improvement > 0 &&
        adjusted.check_one_end_px > 0) {
      j->prepass.pose_check = {adjusted.check_before_px / adjusted.check_one_end_px,
                               adjust_options.check_min_improvement, adjusted.decided_on_frames};
    }
    cam_from_local = adjusted.cam_from_local;
    const Rigid3d local_from_world(Eigen::Quaterniond::Identity(), -j->scene().origin_in_world);
    for (size_t k = 0; k < where.size(); ++k)
      found->poses.push_back({where[k], adjusted.cam_from_local[k] * local_from_world});
  }
  seconds.joint = SecondsSince(step);
  step = std::chrono::steady_clock::now();
  for (PoseAdjustFrame& frame : frames) frame.bgr.release();  // only their cameras are left
  // The depth at full size when the whole capture's fits (painting takes it), and painting
  // looks at the depth.
  size_t depth_bytes = 0;
  for (const PoseAdjustFrame& frame : frames)
    depth_bytes += sizeof(float) * frame.camera->width * frame.camera->height;
  mover_options.full_size_depth =
      project.pipeline.occlusion.enabled && depth_bytes <= kKeepDepthBytes;
  if (movers)
    FRESCO_RETURN_IF_ERROR(FindMoversAcrossViews(project, mover_options, small, frames,
                                                 cam_from_local, where, j, found));
  seconds.movers = SecondsSince(step);
  return Status::Ok();
}

// What the pre-pass found, into the captures (the poses adjusted, each frame's movers) and the
// session (its decisions, in the pre-pass's order); the videos open again for painting.
Status ApplyWholeCapturePrepass(const Project& project, PrepassFound found, PaintJob* j) {
  for (const auto& [where, cam_from_world] : found.poses)
    j->captures[where.first].poses[where.second].cam_from_world = cam_from_world;
  for (size_t s = 0; s < j->captures.size() && s < found.movers.size(); ++s)
    if (!found.movers[s].empty()) j->captures[s].movers = std::move(found.movers[s]);
  if (j->prepass.pose_check) {
    const auto& [ratio, threshold, frames] = *j->prepass.pose_check;
    j->session->SetRefinePoseCheck(ratio, threshold, frames);
  }
  if (j->prepass.background_across_views) {
    const auto& [fraction, frames] = *j->prepass.background_across_views;
    j->session->DecideBackgroundAcrossViews(fraction, frames);
    // No background model, nothing for the masks to join: not kept.
    if (j->session->options().background.mode == BackgroundMode::kOff)
      for (Capture& capture : j->captures) capture.movers.clear();
  }
  const std::vector<StreamSpec> specs = project.Streams();
  for (size_t s = 0; found.read && s < j->captures.size(); ++s)
    FRESCO_RETURN_IF_ERROR(OpenVideoSource(project.Resolve(specs[s].video), &j->captures[s].video));
  return Status::Ok();
}

// The whole-capture pre-pass runs (RunWholeCapturePrepass) rather than being read from
// options.prepass_file.
bool RunsWholeCapturePrepass(const Project& project, const PaintJobOptions& options) {
  return NeedsWholeCapturePrepass(project) &&
         (options.prepass_file.empty() || !std::filesystem::exists(options.prepass_file));
}

// The whole-capture pre-pass, when the project needs one: read from options.prepass_file when
// it exists, else run (or `ran`: run while the session was built) and written there when named.
Status PrepareOrReadPrepass(const Project& project, const PaintJobOptions& options,
                            std::optional<PrepassFound> ran, PaintJob* j) {
  const bool whole_capture = NeedsWholeCapturePrepass(project);
  // Without a pre-pass the file still carries the charts' layout for the shards.
  if (!whole_capture && options.prepass_file.empty()) return Status::Ok();
  const auto start = std::chrono::steady_clock::now();
  bool ran_here = false;
  if (!options.prepass_file.empty() && std::filesystem::exists(options.prepass_file)) {
    FRESCO_RETURN_IF_ERROR(ReadPrepassFile(options.prepass_file, project, j));
  } else {
    if (whole_capture) {
      if (!ran) {
        ran.emplace();
        ran_here = true;
        FRESCO_RETURN_IF_ERROR(RunWholeCapturePrepass(project, options, j, &*ran));
      }
      FRESCO_RETURN_IF_ERROR(ApplyWholeCapturePrepass(project, std::move(*ran), j));
    }
    if (options.prepass_file.empty()) return Status::Ok();
    FRESCO_RETURN_IF_ERROR(WritePrepassFile(options.prepass_file, project, *j));
  }
  const PaintJob::OpenSeconds& seconds = j->open_seconds;
  j->open_seconds.prepass_file =
      SecondsSince(start) - (ran_here ? seconds.read + seconds.joint + seconds.movers : 0.0);
  return Status::Ok();
}

// Which of the capture's poses see each buffer (its bounds in their view), over at most
// kPosesCounted poses spread evenly over the streams' poses in order.
BufferViews ViewsSeeingBuffers(const PaintJob& j,
                               const std::map<const Camera*, NormalizedBounds>& bounds) {
  constexpr size_t kPosesCounted = 512;
  std::vector<std::pair<const Camera*, const Rigid3d*>> views;
  for (const Capture& capture : j.captures)
    for (const PosedImage& pose : capture.poses)
      if (const Camera* camera = capture.CameraFor(pose))
        views.push_back({camera, &pose.cam_from_world});
  const size_t buffers = j.session->buffers().size();
  const size_t step = std::max<size_t>(1, (views.size() + kPosesCounted - 1) / kPosesCounted);
  BufferViews seeing;
  seeing.num_views = static_cast<int>((views.size() + step - 1) / step);
  if (seeing.num_views > 0)
    seeing.frames_per_view = static_cast<double>(views.size()) / seeing.num_views;
  seeing.seen.assign(buffers, std::vector<unsigned long long>((seeing.num_views + 63) / 64, 0));
  seeing.boxes.assign(buffers, {});
  std::vector<std::optional<std::array<float, 4>>> boxes(buffers);
  for (size_t k = 0; k < views.size(); k += step) {
    const auto it = bounds.find(views[k].first);
    if (it == bounds.end()) continue;
    j.session->BufferBoxesInView(*views[k].first, it->second, *views[k].second, &boxes);
    const int v = static_cast<int>(k / step);
    for (size_t b = 0; b < buffers; ++b)
      if (boxes[b]) {
        seeing.Mark(buffers, b, v);
        seeing.boxes[b].push_back({v, *boxes[b]});
      }
  }
  return seeing;
}

// What a shard's work is made of, in nanoseconds of a core, as measured in the 16 shards of a
// city street (2.09 M triangles, 8 streams at 1280x720, 240 frames, 134 M texels; a fit of
// each shard's CPU to the four terms of its ShardWork, within 0.5 s rms, shards of 4.5-10 s):
// a texel held costs ~120 ns (built, written); the warp ~5 ns a texel of a buffer for each
// frame that sees it; a frame ~10 ns a pixel (read, decoded) and ~4 ns a triangle (the mesh
// culled), and ~12 ns a triangle times the share of the image its depth is rendered in, in
// every shard it meets.
ShardCosts ShardCostsFor(const PaintJob& j) {
  double pixels = 0, frames = 0;
  for (const Capture& capture : j.captures)
    for (const PosedImage& pose : capture.poses)
      if (const Camera* camera = capture.CameraFor(pose))
        pixels += static_cast<double>(camera->width) * camera->height, ++frames;
  const double triangles = static_cast<double>(j.scene().mesh.NumTriangles());
  ShardCosts costs;
  costs.per_texel = 120;
  costs.per_texel_frame = 5;
  costs.per_frame = 10.0 * (frames > 0 ? pixels / frames : 0) + 4.0 * triangles;
  costs.per_frame_window = 12.0 * triangles;
  return costs;
}

// PaintJobOptions::paint_at_truth_poses: each pose with a true one of its name takes it.
void TakeTruthPoses(Capture* capture) {
  std::map<std::string, const PosedImage*> truth;
  for (const PosedImage& pose : capture->truth_poses) truth[pose.name] = &pose;
  for (PosedImage& pose : capture->poses)
    if (const auto t = truth.find(pose.name); t != truth.end())
      pose.cam_from_world = t->second->cam_from_world;
}

}  // namespace

bool IsLiveStream(const Project& project, int index) {
  return IsLiveProject(project.ForStream(index));
}

Status OpenPaintJob(const Project& project, const PaintJobOptions& options,
                    std::unique_ptr<PaintJob>* job) {
  if (!options.one_stream_for.empty())
    FRESCO_RETURN_IF_ERROR(CheckOneStream(project, options.one_stream_for));
  auto result = std::make_unique<PaintJob>();
  PaintJob& j = *result;
  j.live = IsLiveProject(project);
  const std::vector<StreamSpec> specs = project.Streams();
  const int num_streams = static_cast<int>(specs.size());
  CaptureLoadOptions load_options;
  load_options.open_live_video = false;  // a live video opens after its pose feed connects
  const auto start = std::chrono::steady_clock::now();
  PaintJob::OpenSeconds& seconds = j.open_seconds;
  if (options.step_started) options.step_started(kLoadStep);
  FRESCO_RETURN_IF_ERROR(LoadStreamCaptures(project, load_options, &j.captures));
  // A shard whose pre-pass file holds the charts' layout lays them out from it, hollow: it
  // builds only the texels it paints (SetOwnBuffers, below).
  std::optional<BufferLayout> layout;
  if (options.shard.sharded() && !options.prepass_file.empty() &&
      std::filesystem::exists(options.prepass_file))
    FRESCO_RETURN_IF_ERROR(
        ReadPrepassLayout(options.prepass_file, project, j.scene().mesh.NumTriangles(), &layout));
  // The whole-capture pre-pass needs the scene and the frames, not the session: it runs while
  // the session's charts and buffers are built (most of that on one core). Only it reports
  // progress meanwhile.
  std::optional<PrepassFound> ran;
  std::future<Status> prepass;
  if (!j.live && !options.paint_at_truth_poses && RunsWholeCapturePrepass(project, options)) {
    ran.emplace();
    prepass = std::async(std::launch::async, [&] {
      try {
        return RunWholeCapturePrepass(project, options, &j, &*ran);
      } catch (const std::exception& e) {
        return Status::Internal(project.file_path + ": pre-pass: " + e.what());
      }
    });
  }
  const Status created =
      CreatePaintSession(project, j.captures, layout ? &*layout : nullptr, &j.session,
                         /*layout_only=*/options.prepass_only && !layout);
  seconds.load = SecondsSince(start);  // the pre-pass's steps have their own times
  const Status prepassed = prepass.valid() ? prepass.get() : Status::Ok();
  FRESCO_RETURN_IF_ERROR(created);
  FRESCO_RETURN_IF_ERROR(prepassed);
  if (options.paint_at_truth_poses)
    for (Capture& capture : j.captures) TakeTruthPoses(&capture);
  const double loaded = SecondsSince(start);
  // Each camera's ray table and the mesh's culling clusters are set-up, not painting: built
  // here, the first frame costs what the others do (a few photos of a large mesh would
  // otherwise show a painting rate set by the first frame).
  if (options.step_started) options.step_started(kCamerasStep);
  for (const Capture& capture : j.captures)
    for (const auto& [id, camera] : capture.cameras) j.session->PrepareCamera(camera);
  seconds.cameras = SecondsSince(start) - loaded;
  if (options.shard.sharded() && j.live)
    return Status::Error(project.file_path +
                         ": --shard paints captures from files (a live stream cannot be split)");
  if (!j.live) {
    FRESCO_RETURN_IF_ERROR(PrepareOrReadPrepass(project, options, std::move(ran), &j));
    // What the pre-pass and the set-up freed goes back to the system before painting: freed
    // on several threads, it stays in their allocators' pools otherwise (the teddy's peak
    // memory 680 -> 880 MB).
    malloc_trim(0);
    std::vector<const Capture*> streams;
    for (const Capture& capture : j.captures) streams.push_back(&capture);
    FileFrameSource::SkipFrame skip;
    if (options.shard.sharded()) {
      // Each camera's frustum bounds, computed here: the skip runs on the reading threads.
      auto bounds = std::make_shared<std::map<const Camera*, NormalizedBounds>>();
      for (const Capture& capture : j.captures)
        for (const auto& [id, camera] : capture.cameras)
          (*bounds)[&camera] = ComputeNormalizedBounds(camera);
      const BufferViews views = ViewsSeeingBuffers(j, *bounds);
      j.buffer_shard =
          AssignBuffersToShards(j.session->buffers(), views, ShardCostsFor(j), options.shard.count);
      j.shard_work = ShardWorks(j.session->buffers(), views, j.buffer_shard,
                                options.shard.count)[options.shard.index];
      j.shard_estimated_s = j.shard_work.Cost(ShardCostsFor(j)) * 1e-9;
      std::vector<bool> own(j.buffer_shard.size());
      for (size_t b = 0; b < own.size(); ++b) own[b] = j.buffer_shard[b] == options.shard.index;
      const auto build = std::chrono::steady_clock::now();
      try {
        j.session->SetOwnBuffers(std::move(own));
      } catch (const std::runtime_error& e) {
        return Status::Error(options.prepass_file + ": layout: " + e.what());
      }
      seconds.load += SecondsSince(build);
      const PaintSession* session = j.session.get();
      skip = [session, bounds](const SourcedFrame& f) {
        const auto it = bounds->find(f.camera);
        return it != bounds->end() && session->PaintsOwnBuffersOnly() &&
               !session->ViewMeetsOwnBuffers(*f.camera, it->second, f.posed.cam_from_world);
      };
    }
    j.source = std::make_unique<FileFrameSource>(project, streams, skip,
                                                 options.read_frames_without_pose, j.decoded);
    seconds.total = SecondsSince(start);
    *job = std::move(result);
    return Status::Ok();
  }
  // Live streams connect at once (each waits for its sources, up to their timeouts).
  j.live_inputs.resize(num_streams);
  std::vector<std::future<Status>> opened(num_streams);
  for (int s = 0; s < num_streams; ++s) {
    if (!IsLiveStream(project, s)) continue;
    const Capture& capture = j.captures[s];
    OffsetEstimator estimator;
    if (capture.cameras.size() == 1)  // else OpenLiveInputs says a live stream needs one
      estimator = MakeTimeOffsetEstimator(
          &j.scene(), capture.cameras.begin()->second, project.pipeline, project.grouping,
          j.session->default_texel_size_m(), TimeOffsetOptions(), project.Resolve(specs[s].video));
    opened[s] = std::async(std::launch::async, [&, s, estimator] {
      return OpenLiveInputs(project.ForStream(s), j.captures[s], estimator,
                            options.keep_tracker_poses, &j.live_inputs[s]);
    });
  }
  Status first_error;
  for (int s = 0; s < num_streams; ++s) {
    if (!opened[s].valid()) continue;
    const Status status = opened[s].get();
    if (first_error.ok() && !status.ok())  // several streams: which one
      first_error = num_streams == 1 ? status
                                     : Status::Error(project.file_path + ": streams[" +
                                                     std::to_string(s) + "]: " + status.message());
  }
  if (!first_error.ok()) return first_error;
  seconds.connect = SecondsSince(start) - loaded - seconds.cameras;
  std::vector<std::unique_ptr<PosedFrameSource>> sources;
  for (int s = 0; s < num_streams; ++s) {
    const Project one = project.ForStream(s);
    const FrameOrigin origin{project.Resolve(specs[s].video), project.Resolve(specs[s].poses)};
    if (j.live_inputs[s].frames)
      sources.push_back(std::make_unique<LiveFrameSource>(&j.live_inputs[s], origin));
    else
      sources.push_back(
          std::make_unique<FileFrameSource>(one, std::vector<const Capture*>{&j.captures[s]}));
  }
  j.source = JoinStreamSources(std::move(sources), options.poll_ms);
  seconds.total = SecondsSince(start);
  *job = std::move(result);
  return Status::Ok();
}

}  // namespace fresco
