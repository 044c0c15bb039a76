#include "pipeline/paint/paint_session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/paint/charts.h"
#include "pipeline/render/renderer.h"

namespace fresco {
namespace {

double MsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// A frame that refinement could not register keeps out of painted texels only when its
// matches show it misaligned by more than this (texels): otherwise it paints as it would
// without refinement. Keeping every unregistered frame out froze each texel at its first
// sample wherever matches were too few (short sequences, small frames: -4.8 dB on a 30-frame
// street with perfect poses, docs/results.md "Evaluation suite"). Perfect poses measure
// 0.15-0.45 texels there, 0.5 degree of noise about 2.
constexpr double kKeepOutMisalignmentPx = 1.0;

bool SameCamera(const Camera& a, const Camera& b) {
  return a.width == b.width && a.height == b.height && a.Params() == b.Params() &&
         a.model == b.model;
}

cv::Mat DepthDebugImage(const cv::Mat& depth) {
  cv::Mat finite = depth.clone();
  cv::Mat mask = depth < 1e30f;
  double lo = 0, hi = 1;
  cv::minMaxLoc(depth, &lo, &hi, nullptr, nullptr, mask);
  finite.setTo(hi, ~mask);
  cv::Mat gray;
  finite.convertTo(gray, CV_8U, hi > lo ? -255.0 / (hi - lo) : 0,
                   hi > lo ? 255.0 * hi / (hi - lo) : 0);
  cv::Mat colour;
  cv::applyColorMap(gray, colour, cv::COLORMAP_VIRIDIS);
  colour.setTo(cv::Scalar(0, 0, 0), ~mask);
  return colour;
}

}  // namespace

double AutomaticTexelSize(const Scene& scene, const Camera& camera,
                          const std::vector<Rigid3d>& cam_from_world) {
  const double f = camera.fx > 0 ? 0.5 * (camera.fx + camera.fy) : 500.0;
  Eigen::Vector3d lo, hi;
  scene.Bounds(&lo, &hi);
  if (cam_from_world.empty() || camera.width <= 0 || camera.height <= 0)
    return std::max(0.5 * (hi - lo).norm() / f, 1e-6);
  // The depth actually seen: rasterize up to 16 of the poses through the camera scaled down
  // 8 times, and take the median depth over all surface samples. A pixel covers z / f
  // metres there: one texel per pixel at the typical distance.
  const int scale = 8;
  Camera small = camera;
  small.width = std::max(1, camera.width / scale);
  small.height = std::max(1, camera.height / scale);
  const double sx = static_cast<double>(small.width) / camera.width;
  const double sy = static_cast<double>(small.height) / camera.height;
  small.fx *= sx, small.fy *= sy;
  small.cx = (camera.cx + 0.5) * sx - 0.5, small.cy = (camera.cy + 0.5) * sy - 0.5;
  std::vector<float> depths;
  try {
    const Rasterizer raster(small, RasterOptions());
    RasterOutput out;
    const size_t step = std::max<size_t>(1, cam_from_world.size() / 16);
    for (size_t i = 0; i < cam_from_world.size(); i += step) {
      raster.Rasterize(scene.mesh, CamFromLocal(scene, cam_from_world[i]), &out);
      for (int y = 0; y < out.depth.rows; ++y)
        for (int x = 0; x < out.depth.cols; ++x)
          if (const float z = out.depth.at<float>(y, x); std::isfinite(z)) depths.push_back(z);
    }
  } catch (const std::invalid_argument&) {
  }
  // Seeing the whole mesh, the rasterizer's set-ups would hold ~110 bytes per triangle for
  // the rest of the run (370 MB for 3.2 M triangles); painting never needs them.
  Rasterizer::ReleaseThreadScratch();
  double d = 0.5 * (hi - lo).norm();
  if (!depths.empty()) {
    std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
    d = depths[depths.size() / 2];
  }
  return std::max(d / f, 1e-6);
}

Status PaintSession::Create(const PaintSessionInputs& inputs,
                            std::unique_ptr<PaintSession>* session) {
  std::unique_ptr<PaintSession> s(new PaintSession());
  s->scene_ = inputs.scene;
  s->options_ = inputs.pipeline;
  s->requested_refine_ = inputs.pipeline.refine.mode;
  s->requested_background_ = inputs.pipeline.background.mode;
  s->expected_frames_ = static_cast<int>(inputs.expected_poses.size());
  s->options_.background.warmup_frames = EffectiveWarmupFrames(inputs);
  const TriangleMesh& mesh = inputs.scene->mesh;
  if (mesh.NumTriangles() == 0) return Status::Error(inputs.scene->source_path + ": no triangles");
  s->texel_size_m_ =
      inputs.pipeline.texel_size_m > 0
          ? inputs.pipeline.texel_size_m
          : (inputs.typical_camera
                 ? AutomaticTexelSize(*inputs.scene, *inputs.typical_camera, inputs.expected_poses)
                 : 0.01);
  Grouping grouping;
  ChartScale chart_scale;
  chart_scale.texel_size_m = s->texel_size_m_;
  chart_scale.max_chart_texels = inputs.pipeline.max_buffer_texels;
  FRESCO_RETURN_IF_ERROR(MakeGrouping(mesh, inputs.grouping, chart_scale, &grouping));
  BaseBufferOptions buffer_options;
  buffer_options.texel_size_m = s->texel_size_m_;
  buffer_options.max_buffer_texels = inputs.pipeline.max_buffer_texels;
  buffer_options.max_side_texels = MaxBufferSide(inputs.pipeline.atlas);
  s->set_ = BuildBaseBuffers(mesh, grouping, buffer_options);
  std::vector<cv::Size> sizes;
  for (const BaseBuffer& b : s->set_.buffers) sizes.emplace_back(b.width, b.height);
  FRESCO_RETURN_IF_ERROR(PackAtlas(sizes, inputs.pipeline.atlas, &s->atlas_));
  s->painted_.resize(s->set_.buffers.size());
  s->anchors_.resize(s->set_.buffers.size());
  for (size_t b = 0; b < s->set_.buffers.size(); ++b)
    InitRefineAnchor(s->set_.buffers[b], &s->anchors_[b]);
  s->warped_.resize(s->set_.buffers.size());
  for (size_t b = 0; b < s->set_.buffers.size(); ++b)
    InitPaintedBuffer(s->set_.buffers[b], &s->painted_[b]);
  s->StartAutoModes();
  *session = std::move(s);
  return Status::Ok();
}

void PaintSession::ResetPainting() {
  for (size_t b = 0; b < set_.buffers.size(); ++b) {
    InitPaintedBuffer(set_.buffers[b], &painted_[b]);
    InitRefineAnchor(set_.buffers[b], &anchors_[b]);
  }
  StartAutoModes();
  frames_seen_ = 0;
  exposure_gain_sum_ = exposure_offset_sum_ = cv::Vec3d(0, 0, 0);
  exposure_frames_ = 0;
}

void PaintSession::StartAutoModes() {
  const bool refine_auto = requested_refine_ == RefineMode::kAuto;
  const bool background_auto = requested_background_ == BackgroundMode::kAuto;
  options_.refine.mode = refine_auto ? RefineMode::kRobust : requested_refine_;
  options_.background.mode = background_auto ? BackgroundMode::kRobust : requested_background_;
  refine_auto_.Start(refine_auto);
  background_auto_.Start(background_auto, options_.background.warmup_frames, expected_frames_);
  if (refine_auto && options_.select.enabled && options_.update == UpdatePolicy::kQuality) {
    refine_auto_.DecideOff(0);  // view selection runs without refinement (SelectActive)
    options_.refine.mode = RefineMode::kOff;
  }
  background_.clear();
  background_frame_.clear();
  if (options_.background.mode != BackgroundMode::kOff) {
    background_frame_.resize(set_.buffers.size());
    StreamBackground(0);  // every project has a stream 0: its set-up is not the first frame's
  }
}

std::vector<BufferBackground>& PaintSession::StreamBackground(int stream) {
  if (stream < 0) throw std::invalid_argument("PaintSession: stream " + std::to_string(stream));
  if (background_.size() <= static_cast<size_t>(stream)) background_.resize(stream + 1);
  std::vector<BufferBackground>& models = background_[stream];
  if (models.empty()) {
    models.resize(set_.buffers.size());
    for (size_t b = 0; b < set_.buffers.size(); ++b)
      models[b].Init(set_.buffers[b], options_.background);
  }
  return models;
}

void PaintSession::UpdateAutoModes(int frame_number, double misalignment_px,
                                   const std::vector<bool>& seen, FrameReport* report) {
  if (refine_auto_.AddFrame(frame_number, misalignment_px) &&
      refine_auto_.decision().state == AutoDecision::State::kOff)
    options_.refine.mode = RefineMode::kOff;  // no further cost
  if (background_auto_.deciding() && options_.background.mode != BackgroundMode::kOff) {
    long long observed = 0, warming = 0, masked = 0;
    for (size_t b = 0; b < seen.size(); ++b) {
      if (!seen[b]) continue;
      observed += background_frame_[b].observed;
      warming += background_frame_[b].warming_up;
      masked += background_frame_[b].masked;
    }
    if (background_auto_.AddFrame(frame_number, observed, warming, masked) &&
        background_auto_.decision().state == AutoDecision::State::kOff) {
      options_.background.mode = BackgroundMode::kOff;  // painting continues as `off`
      background_.clear();
      background_frame_.clear();
    }
  }
  report->decisions = auto_decisions();
  if (StageReport* refine = report->Stage("refine")) report->decisions.refine.PutInto(refine);
  if (StageReport* background = report->Stage("background"))
    report->decisions.background.PutInto(background);
}

const PaintSession::CameraCache& PaintSession::CacheFor(const Camera& camera) {
  for (const CameraCache& cache : cameras_)
    if (SameCamera(cache.camera, camera)) return cache;
  RasterOptions options;
  options.near_m = 1e-3;
  cameras_.push_back(CameraCache{camera, std::make_unique<Rasterizer>(camera, options),
                                 ComputeNormalizedBounds(camera)});
  return cameras_.back();
}

// The indices where `flags` is true.
static std::vector<size_t> Indices(const std::vector<bool>& flags) {
  std::vector<size_t> out;
  for (size_t i = 0; i < flags.size(); ++i)
    if (flags[i]) out.push_back(i);
  return out;
}

void PaintSession::ForEachBuffer(const std::vector<size_t>& todo, bool serial,
                                 const std::function<void(size_t)>& fn) const {
  // A buffer of this many chunks (16 x 16 texels each) keeps both cores busy on its own.
  constexpr size_t kLargeBufferChunks = 64;
  std::vector<size_t> small;
  for (size_t b : todo) {
    if (serial || set_.buffers[b].chunks.size() >= kLargeBufferChunks)
      fn(b);  // parallel inside
    else
      small.push_back(b);
  }
  // Small buffers one per task: their own parallel loops run inline (OpenCV does not nest).
  cv::parallel_for_(
      cv::Range(0, static_cast<int>(small.size())),
      [&](const cv::Range& range) {
        for (int i = range.start; i < range.end; ++i) fn(small[i]);
      },
      static_cast<double>(small.size()));
}

void PaintSession::PaintFrame(const Frame& frame, const Camera& camera,
                              const Rigid3d& cam_from_world, int stream, FrameReport* report) {
  const auto frame_start = std::chrono::steady_clock::now();
  report->frame = frame.index;
  report->name = frame.name;
  report->stages.clear();
  report->paint = PaintFigures();
  report->refine = RefineFigures();
  report->background = BackgroundFigures();
  const int frame_number = frames_seen_++;
  if (options_.update_every > 1 && frame_number % options_.update_every != 0) {
    report->painted = false;
    report->skipped_reason = "update_every";
    return;
  }
  const bool debug = options_.debug_images;
  const Rigid3d cam_from_local = CamFromLocal(*scene_, cam_from_world);

  // 1. depth
  auto start = std::chrono::steady_clock::now();
  StageReport depth_report;
  depth_report.name = "depth";
  const CameraCache& camera_cache = CacheFor(camera);
  if (options_.occlusion.enabled) {
    camera_cache.rasterizer->RasterizeDepth(scene_->mesh, cam_from_local, &depth_);
    if (debug)
      depth_report.metrics["surface_pixels"] =
          cv::countNonZero(depth_ < std::numeric_limits<float>::infinity());
    if (debug) depth_report.images["depth"] = DepthDebugImage(depth_);
  }
  depth_report.wall_ms = MsSince(start);
  report->stages.push_back(std::move(depth_report));

  // 2. warp
  start = std::chrono::steady_clock::now();
  StageReport warp_report;
  warp_report.name = "warp";
  FrameView view;
  view.camera = &camera;
  view.cam_from_local = cam_from_local;
  view.centre_local = cam_from_local.Centre();
  view.frame_bgr = &frame.bgr;
  view.depth = options_.occlusion.enabled ? &depth_ : nullptr;
  view.bounds = camera_cache.bounds;
  if (options_.sampling == SamplingMode::kArea) {
    view.pyramid.push_back(frame.bgr);
    while (view.pyramid.size() < 6 && view.pyramid.back().cols > 16) {
      cv::Mat down;
      cv::pyrDown(view.pyramid.back(), down);
      view.pyramid.push_back(down);
    }
  }
  WarpOptions warp_options;
  warp_options.sampling = options_.sampling;
  warp_options.occlusion = options_.occlusion;
  long long in_view = 0, visible = 0, occluded = 0, grazing = 0, buffers_seen = 0;
  long long tested = 0, chunks_culled = 0;
  std::vector<bool> seen(set_.buffers.size(), false);
  // Buffers whose bounds lie outside the view frustum are skipped whole (no work, not even
  // clearing their warped images: later stages look only at buffers seen).
  std::vector<size_t> in_frustum;
  for (size_t b = 0; b < set_.buffers.size(); ++b)
    if (!BoundsOutsideView(set_.buffers[b].bounds_min, set_.buffers[b].bounds_max, view,
                           warp_options.near_m))
      in_frustum.push_back(b);
  // When no stage looks at the warped samples before the paint stage (no background
  // model, no refinement, no exposure or view selection, no debug images), the warp paints
  // them directly: the same texels, without writing and reading back the warped images.
  const bool background = options_.background.mode != BackgroundMode::kOff;
  const bool paint_in_warp =
      !background && options_.refine.mode == RefineMode::kOff && !SelectActive(options_) && !debug;
  const TexelUpdateRule rule = TexelUpdateRule::From(options_);
  if (paint_in_warp && view.depth && !in_frustum.empty() &&
      options_.sampling == SamplingMode::kBilinear) {
    DepthRange2x2(depth_, &depth_range_);  // one pair per texel instead of four depths
    view.depth_range = &depth_range_;
  }
  std::vector<PaintUpdateStats> paint_stats(set_.buffers.size());
  ForEachBuffer(in_frustum, false, [&](size_t b) {
    if (paint_in_warp)
      paint_stats[b] =
          WarpAndPaintBuffer(set_.buffers[b], view, warp_options, rule, &warped_[b], &painted_[b]);
    else
      WarpFrameToBuffer(set_.buffers[b], view, warp_options, &warped_[b]);
  });
  for (size_t b : in_frustum) {
    in_view += warped_[b].in_view;
    visible += warped_[b].visible;
    occluded += warped_[b].occluded;
    grazing += warped_[b].grazing;
    tested += warped_[b].texels_tested;
    chunks_culled += warped_[b].chunks_culled;
    if (warped_[b].visible > 0) {
      seen[b] = true;
      ++buffers_seen;
      if (debug) {
        cv::Mat warped(warped_[b].bgr.size(), CV_8UC3, cv::Scalar(64, 64, 64));  // unseen: grey
        warped_[b].bgr.copyTo(warped, warped_[b].valid);
        warp_report.images["warped_b" + std::to_string(b)] = warped;
        warp_report.images["visible_b" + std::to_string(b)] = warped_[b].valid.clone();
      }
    }
  }
  warp_report.metrics["buffers_culled"] =
      static_cast<double>(set_.buffers.size() - in_frustum.size());
  warp_report.metrics["texels_in_view"] = static_cast<double>(in_view);
  warp_report.metrics["texels_visible"] = static_cast<double>(visible);
  warp_report.metrics["texels_occluded"] = static_cast<double>(occluded);
  warp_report.metrics["texels_grazing"] = static_cast<double>(grazing);
  warp_report.metrics["buffers_seen"] = static_cast<double>(buffers_seen);
  warp_report.metrics["texels_tested"] = static_cast<double>(tested);
  warp_report.metrics["chunks_culled"] = static_cast<double>(chunks_culled);
  warp_report.wall_ms = MsSince(start);
  report->stages.push_back(std::move(warp_report));

  // 3. refine
  frame_camera_ = &camera;
  frame_cam_from_local_ = cam_from_local;
  double measured_misalignment_px = -1;  // refine.mode auto, deciding
  if (options_.refine.mode != RefineMode::kOff) {
    const bool measure_only = refine_auto_.deciding();
    if (measure_only || frame_number % options_.refine.every_n_frames == 0) {
      report->stages.push_back(RefineAlignment(seen, debug, measure_only, &report->refine));
      if (measure_only) measured_misalignment_px = frame_misalignment_px_;
    } else {  // not registered this frame: it only fills what the buffers lack
      for (size_t b = 0; b < set_.buffers.size(); ++b)
        if (seen[b]) KeepOutOfPainted(b, warped_[b].valid_box);
    }
  }

  // 3b. exposure
  const bool select = SelectActive(options_);
  if (select && options_.select.exposure) report->stages.push_back(CorrectExposure(Indices(seen)));

  // 4. background
  if (background)
    report->stages.push_back(SegmentForeground(seen, stream, debug, &report->background));

  // 4b. select
  if (select) report->stages.push_back(SelectViewsStage(Indices(seen)));

  // 5. paint
  start = std::chrono::steady_clock::now();
  StageReport paint_report;
  paint_report.name = "paint";
  long long written = 0, rejected = 0, compared = 0;
  double difference_sum = 0;
  const std::vector<size_t> seen_list = Indices(seen);
  if (paint_in_warp) {
    paint_report.notes["painted"] = "during the warp (no stage between them)";
  } else {
    ForEachBuffer(seen_list, false, [&](size_t b) {
      const cv::Mat mask = !background || background_frame_[b].masked == 0
                               ? cv::Mat()
                               : background_frame_[b].foreground;
      const cv::Mat warming = !background || background_frame_[b].warming_up == 0
                                  ? cv::Mat()
                                  : background_frame_[b].warming;
      paint_stats[b] =
          PaintBuffer(set_.buffers[b], warped_[b], mask, options_, &painted_[b], warming);
      if (background) MarkProvisional(background_frame_[b], warped_[b].valid_box, &painted_[b]);
    });
  }
  for (size_t b : seen_list) {
    const PaintUpdateStats& stats = paint_stats[b];
    written += stats.written;
    rejected += stats.rejected;
    compared += stats.compared;
    difference_sum += stats.abs_grey_difference_sum;
    if (debug) paint_report.images["painted_b" + std::to_string(b)] = painted_[b].bgra.clone();
  }
  paint_report.metrics["texels_written"] = static_cast<double>(written);
  paint_report.metrics["texels_kept_sharper"] = static_cast<double>(rejected);
  // Mean |grey difference| between this frame and what the buffers held, where both exist:
  // a cheap misalignment signal (pose error, exposure change, movers), NaN when none.
  if (compared > 0) report->paint.difference_to_buffer = difference_sum / compared;
  report->paint.PutInto(&paint_report);
  paint_report.metrics["coverage"] = Coverage();
  paint_report.wall_ms = MsSince(start);
  report->stages.push_back(std::move(paint_report));
  UpdateAutoModes(frame_number, measured_misalignment_px, seen, report);
  report->painted = true;
  report->total_ms = MsSince(frame_start);
}

void PaintSession::KeepOutOfPainted(size_t b, const cv::Rect& roi) {
  if (roi.empty()) return;
  cv::Mat alpha;
  cv::extractChannel(painted_[b].bgra(roi), alpha, 3);
  warped_[b].valid(roi).setTo(0, alpha);
}

// One buffer's refinement: register, warp again, anchor; what the stage reports about it.
struct PaintSession::BufferRefinement {
  RefineEstimate estimate;
  bool moved = false, kept_out = false;
  double estimate_ms = 0, rewarp_ms = 0, anchor_ms = 0;
  std::map<std::string, cv::Mat> images;
};

void PaintSession::EstimateBuffer(size_t b, bool debug, BufferRefinement* r) {
  const WarpedBuffer& w = warped_[b];
  const PaintedBuffer& painted = painted_[b];
  RefineEstimate& e = r->estimate;
  const auto t0 = std::chrono::steady_clock::now();
  e = EstimateRefinement(w.bgr, w.valid, painted.bgra, options_.refine, w.valid_box);
  r->estimate_ms = MsSince(t0);
  if (debug && e.inliers > 0)
    r->images["residual_before_b" + std::to_string(b)] =
        ResidualHeatMap(w.bgr, w.valid, painted.bgra, e.region);
}

void PaintSession::FinishBuffer(size_t b, bool debug, BufferRefinement* r) {
  WarpedBuffer& w = warped_[b];
  PaintedBuffer& painted = painted_[b];
  RefineEstimate& e = r->estimate;
  const std::string suffix = "_b" + std::to_string(b);
  auto t0 = std::chrono::steady_clock::now();
  w.valid_box = ApplyRefinement(e, w.valid_box, &w.bgr, &w.valid, &w.quality);
  r->rewarp_ms = MsSince(t0);
  t0 = std::chrono::steady_clock::now();
  // A registered frame is a sample of the buffer's offset (refine_anchor.h).
  AnchorMove move;
  std::vector<cv::Point2f> inliers_at;
  for (size_t i = 0; i < e.to.size(); ++i)
    if (e.inlier[i]) inliers_at.push_back(e.to[i]);
  if (options_.refine.anchor && e.registered &&
      AddAnchorSample(e.buffer_from_warped, inliers_at, options_.refine, &anchors_[b], &move)) {
    MovePaintedBuffer(move, anchors_[b], &painted);
    // The frame, registered to the buffer before the move, moves with it.
    const int margin = static_cast<int>(std::ceil(e.correction_px)) + 2;
    const cv::Rect within =
        cv::Rect(w.valid_box.x - margin, w.valid_box.y - margin, w.valid_box.width + 2 * margin,
                 w.valid_box.height + 2 * margin) &
        cv::Rect(0, 0, w.valid.cols, w.valid.rows);
    MoveWarpedImages(move, within, &w.bgr, &w.valid, &w.quality);
    w.valid_box = within;  // valid texels may have moved by up to the margin
    // Every stream's model of the buffer moves with it (a stream's set made later starts
    // in the moved buffer).
    if (!background_.empty() && TakeBackgroundMove(&anchors_[b], &move))
      for (std::vector<BufferBackground>& models : background_)
        if (!models.empty()) models[b].Move(set_.buffers[b], move.roi, move.field);
    r->moved = true;
  }
  r->anchor_ms = MsSince(t0);
  const bool misaligned = (e.inliers > 0 && e.residual_before_px > kKeepOutMisalignmentPx) ||
                          frame_misalignment_px_ > kKeepOutMisalignmentPx;
  if (!e.registered && !e.region.empty() && misaligned) {
    // Not registered and seen misaligned: it may fill what the buffer lacks but not overwrite
    // registered texels (which all lie in the region: it bounds where the frame and the
    // buffer overlap).
    KeepOutOfPainted(b, e.region);
    r->kept_out = true;
  }
  if (debug) {
    r->images["matches" + suffix] = DrawRefinementMatches(w.bgr, e);
    if (e.inliers > 0)
      r->images["residual_after" + suffix] =
          ResidualHeatMap(w.bgr, w.valid, painted.bgra, e.region);
  }
}

void PaintSession::CorrectThroughPose(const std::vector<size_t>& todo,
                                      const std::vector<size_t>& fresh, bool measure_only,
                                      std::vector<BufferRefinement>* results, StageReport* report) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<PoseMatch> matches;
  for (size_t i = 0; i < todo.size(); ++i)
    AppendPoseMatches(set_.buffers[todo[i]], *frame_camera_, frame_cam_from_local_,
                      (*results)[i].estimate, &matches);
  const PoseCorrection pose =
      EstimatePoseCorrection(matches, *frame_camera_, frame_cam_from_local_, options_.refine);
  report->metrics["pose_matches"] = pose.matches;
  report->metrics["pose_inliers"] = pose.inliers;
  report->metrics["pose_residual_before_px"] = pose.residual_before_px;
  report->metrics["pose_residual_after_px"] = pose.residual_after_px;
  report->metrics["pose_rotation_deg"] =
      Rigid3d::AxisAngleFromQuaternion(pose.delta.rotation).norm() * 180.0 / M_PI;
  report->metrics["pose_translation_m"] = pose.delta.translation.norm();
  report->metrics["pose_model_" + pose.model] = 1;
  report->notes["pose"] = pose.applied ? pose.model : "no pose correction: " + pose.fallback;
  if (pose.inliers > 0) frame_misalignment_px_ = pose.residual_before_px;
  if (!pose.applied || measure_only) return;  // the buffers keep their own 2D estimates
  const Rigid3d corrected = pose.delta * frame_cam_from_local_;
  results->resize(todo.size() + fresh.size());
  for (size_t i = 0; i < results->size(); ++i) {
    const size_t b = i < todo.size() ? todo[i] : fresh[i - todo.size()];
    RefineEstimate& e = (*results)[i].estimate;
    const cv::Rect& box = warped_[b].valid_box;
    cv::Matx33d H;
    if (!BufferCorrectionFromPose(set_.buffers[b], *frame_camera_, frame_cam_from_local_, corrected,
                                  box, &H)) {
      continue;  // keeps its own estimate
    }
    e.buffer_from_warped = H;
    e.model = MotionModel::kHomography;
    e.registered = true;
    e.correction_px = LargestDisplacement(H, box);
    e.applied = e.correction_px >= options_.refine.min_correction_px;
    e.fallback = e.applied ? "" : "none needed (below min_correction_px)";
    e.residual_after_px = InlierResidualPx(e, H);
  }
  report->metrics["pose_ms"] = MsSince(start);
}

// Refinement measuring for its `auto` decision registers at most about this many texels a
// frame (the largest buffers seen, whole).
constexpr long long kMeasureTexels = 300000;

StageReport PaintSession::RefineAlignment(const std::vector<bool>& seen, bool debug,
                                          bool measure_only, RefineFigures* figures) {
  const auto start = std::chrono::steady_clock::now();
  StageReport report;
  report.name = "refine";
  frame_misalignment_px_ = -1;
  std::vector<size_t> todo, fresh;
  for (size_t b = 0; b < set_.buffers.size(); ++b) {
    if (seen[b] && painted_[b].painted_surface_texels > 0)
      todo.push_back(b);
    else if (seen[b])
      fresh.push_back(b);
  }
  if (measure_only) {
    // Measuring needs a sample, not every buffer: the largest regions seen, up to about a
    // 640x480 frame's texels (a photo of a large mesh sees several times that).
    std::stable_sort(todo.begin(), todo.end(), [&](size_t a, size_t b) {
      return warped_[a].valid_box.area() > warped_[b].valid_box.area();
    });
    long long area = 0;
    size_t kept = 0;
    while (kept < todo.size() && area < kMeasureTexels)
      area += warped_[todo[kept++]].valid_box.area();
    todo.resize(kept);
    std::sort(todo.begin(), todo.end());
  }
  // Buffers are independent: one per thread, the largest regions first so that the threads
  // finish together (longest processing time first).
  std::vector<BufferRefinement> results(todo.size());
  const auto for_each_buffer = [&](void (PaintSession::*step)(size_t, bool, BufferRefinement*)) {
    std::vector<int> order(todo.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
      return warped_[todo[a]].valid_box.area() > warped_[todo[b]].valid_box.area();
    });
    cv::parallel_for_(
        cv::Range(0, static_cast<int>(order.size())),
        [&](const cv::Range& range) {
          for (int i = range.start; i < range.end; ++i)
            (this->*step)(todo[order[i]], debug, &results[order[i]]);
        },
        static_cast<double>(order.size()));
  };
  if (options_.refine.pose) {  // every buffer's matches first, then one pose for all
    for_each_buffer(&PaintSession::EstimateBuffer);
    CorrectThroughPose(todo, fresh, measure_only, &results, &report);
    if (results.size() > todo.size()) todo.insert(todo.end(), fresh.begin(), fresh.end());
    if (!measure_only) for_each_buffer(&PaintSession::FinishBuffer);
  } else {  // each buffer on its own; the frame's misalignment pooled over their inliers
    for_each_buffer(&PaintSession::EstimateBuffer);
    double sum_sq = 0;
    int pooled = 0;
    for (const BufferRefinement& r : results) {
      sum_sq += r.estimate.inliers * r.estimate.residual_before_px * r.estimate.residual_before_px;
      pooled += r.estimate.inliers;
    }
    if (pooled > 0) frame_misalignment_px_ = std::sqrt(sum_sq / pooled);
    if (!measure_only) for_each_buffer(&PaintSession::FinishBuffer);
  }

  int refined = 0, fell_back = 0, corners = 0, matches = 0, inliers = 0, ambiguous = 0, moved = 0,
      unregistered_kept_out = 0;
  double before_sq = 0, after_sq = 0, correction = 0;
  double estimate_ms = 0, rewarp_ms = 0, anchor_ms = 0;
  std::map<std::string, int> models, reasons;
  for (size_t i = 0; i < todo.size(); ++i) {
    const RefineEstimate& e = results[i].estimate;
    report.images.merge(results[i].images);
    estimate_ms += results[i].estimate_ms;
    rewarp_ms += results[i].rewarp_ms;
    anchor_ms += results[i].anchor_ms;
    moved += results[i].moved;
    unregistered_kept_out += results[i].kept_out;
    corners += e.corners, matches += e.matches, inliers += e.inliers, ambiguous += e.ambiguous;
    before_sq += e.inliers * e.residual_before_px * e.residual_before_px;
    after_sq += e.inliers * e.residual_after_px * e.residual_after_px;
    if (e.applied && !measure_only) {
      ++refined;
      ++models[MotionModelName(e.model)];
      correction = std::max(correction, e.correction_px);
    } else {
      ++fell_back;
      ++reasons[e.fallback];
    }
    if (debug)
      report.notes["buffer" + std::to_string(todo[i])] =
          (e.applied ? MotionModelName(e.model) : "no correction: " + e.fallback) + " (" +
          std::to_string(e.inliers) + "/" + std::to_string(e.matches) + " inliers)";
  }
  report.metrics["buffers_refined"] = refined;
  report.metrics["buffers_not_refined"] = fell_back;
  report.metrics["corners"] = corners;
  report.metrics["matches"] = matches;
  report.metrics["inliers"] = inliers;
  report.metrics["ambiguous_matches"] = ambiguous;  // dropped: repetitive texture
  // RMS over all inliers, texels: identity before, the chosen corrections after.
  if (inliers > 0) {
    figures->residual_before_px = std::sqrt(before_sq / inliers);
    figures->residual_after_px = std::sqrt(after_sq / inliers);
  }
  figures->PutInto(&report);
  report.metrics["correction_px"] = correction;
  report.metrics["buffers_moved"] = moved;
  report.metrics["buffers_unregistered"] = unregistered_kept_out;
  // Thread time summed over the buffers (they run in parallel): corners, matching and
  // fitting; warping the frame again; consensus and buffer moves.
  report.metrics["estimate_ms"] = estimate_ms;
  report.metrics["rewarp_ms"] = rewarp_ms;
  report.metrics["anchor_ms"] = anchor_ms;  // consensus anchoring moved them this frame
  for (const auto& [model, n] : models) report.metrics["model_" + model] = n;
  std::string why;
  for (const auto& [reason, n] : reasons)
    why += (why.empty() ? "" : "; ") + reason + " x" + std::to_string(n);
  if (!why.empty()) report.notes["not refined"] = why;
  if (measure_only) report.notes["not refined"] = "measured only (refine.mode auto, deciding)";
  report.wall_ms = MsSince(start);
  return report;
}

StageReport PaintSession::SegmentForeground(const std::vector<bool>& seen, int stream, bool debug,
                                            BackgroundFigures* figures) {
  const auto start = std::chrono::steady_clock::now();
  StageReport report;
  report.name = "background";
  std::vector<BufferBackground>& models = StreamBackground(stream);
  float gain = 1.0f;
  if (options_.background.mode == BackgroundMode::kRobust && options_.background.normalize_gain) {
    // One histogram per buffer seen, in parallel, summed in buffer order (integer counts:
    // the same whatever the threads).
    const std::vector<size_t> seen_buffers = Indices(seen);
    std::vector<GainHistogram> per_buffer(seen_buffers.size());
    cv::parallel_for_(cv::Range(0, static_cast<int>(seen_buffers.size())),
                      [&](const cv::Range& range) {
                        for (int i = range.start; i < range.end; ++i) {
                          const size_t b = seen_buffers[i];
                          models[b].AccumulateGain(set_.buffers[b], warped_[b], &per_buffer[i]);
                        }
                      });
    GainHistogram histogram;
    for (const GainHistogram& h : per_buffer) {
      for (int i = 0; i < GainHistogram::kBins; ++i) histogram.bins[i] += h.bins[i];
      histogram.count += h.count;
    }
    gain = histogram.MedianGain();
  }
  long long observed = 0, raw = 0, masked = 0, warming = 0, blobs = 0;
  const std::vector<size_t> seen_list = Indices(seen);
  ForEachBuffer(seen_list, false, [&](size_t b) {
    models[b].Update(set_.buffers[b], warped_[b], gain, debug, &background_frame_[b]);
  });
  for (size_t b : seen_list) {
    const BackgroundFrame& frame = background_frame_[b];
    observed += frame.observed, raw += frame.foreground_raw, masked += frame.masked;
    warming += frame.warming_up, blobs += frame.blobs_removed;
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
  report.wall_ms = MsSince(start);
  return report;
}

cv::Mat PaintSession::BackgroundImage(size_t b, int stream) const {
  if (stream < 0 || static_cast<size_t>(stream) >= background_.size()) return cv::Mat();
  const std::vector<BufferBackground>& models = background_[stream];
  return b < models.size() ? models[b].Image(set_.buffers[b]) : cv::Mat();
}

long long PaintSession::NumSurfaceTexels() const {
  long long n = 0;
  for (const auto& b : set_.buffers) n += b.num_surface_texels;
  return n;
}

long long PaintSession::NumPaintedSurfaceTexels() const {
  long long n = 0;
  for (const auto& p : painted_) n += p.painted_surface_texels;
  return n;
}

double PaintSession::Coverage() const {
  const long long total = NumSurfaceTexels();
  return total > 0 ? static_cast<double>(NumPaintedSurfaceTexels()) / total : 0.0;
}

// The scene's geometry with no UVs, every triangle on material 0: transparent (never
// painted) until a buffer's material replaces it.
static Scene UnpaintedCopy(const Scene& scene) {
  Scene out;
  out.origin_in_world = scene.origin_in_world;
  out.source_path = scene.source_path;
  out.mesh = scene.mesh;
  const int n = scene.mesh.NumTriangles();
  out.mesh.uvs.assign(n,
                      {Eigen::Vector2f::Zero(), Eigen::Vector2f::Zero(), Eigen::Vector2f::Zero()});
  out.mesh.has_uv.assign(n, false);
  out.mesh.material.assign(n, 0);
  Material unpainted;
  unpainted.name = "unpainted";
  unpainted.base_color_factor = Eigen::Vector4d(1, 1, 1, 0);
  out.materials.push_back(unpainted);
  return out;
}

Scene PaintSession::PaintedScene() const {
  Scene out = UnpaintedCopy(*scene_);
  const TriangleMesh& mesh = scene_->mesh;
  std::vector<cv::Mat> images(painted_.size());
  for (size_t b = 0; b < painted_.size(); ++b) images[b] = AtMeanExposure(painted_[b].bgra);
  for (size_t page = 0; page < atlas_.pages.size(); ++page) {
    Texture texture;
    texture.name = "page_" + std::to_string(page);
    cv::cvtColor(ComposeAtlasPage(atlas_, static_cast<int>(page), images), texture.rgba,
                 cv::COLOR_BGRA2RGBA);
    texture.wrap_s = texture.wrap_t = TextureWrap::kClampToEdge;
    out.textures.push_back(texture);
    Material material;
    material.name = texture.name;
    material.base_color_texture = static_cast<int>(page);
    out.materials.push_back(material);
  }
  for (size_t b = 0; b < set_.buffers.size(); ++b) {
    const BaseBuffer& buffer = set_.buffers[b];
    const AtlasPlacement& place = atlas_.placements[b];
    if (place.page < 0) continue;
    const cv::Size page = atlas_.pages[place.page];
    for (int t : buffer.triangles) {
      out.mesh.material[t] = place.page + 1;
      out.mesh.has_uv[t] = true;
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector2d q = buffer.TexelCoords(mesh.Corner(t, k));
        out.mesh.uvs[t][k] = Eigen::Vector2f(static_cast<float>((place.x + q.x()) / page.width),
                                             static_cast<float>((place.y + q.y()) / page.height));
      }
    }
  }
  return out;
}

Scene PaintSession::PaintedSceneByBuffer() const {
  Scene out = UnpaintedCopy(*scene_);
  const TriangleMesh& mesh = scene_->mesh;
  for (size_t b = 0; b < set_.buffers.size(); ++b) {
    const BaseBuffer& buffer = set_.buffers[b];
    Texture texture;
    texture.name = "buffer_" + std::to_string(b);
    cv::cvtColor(AtMeanExposure(painted_[b].bgra), texture.rgba, cv::COLOR_BGRA2RGBA);
    texture.wrap_s = texture.wrap_t = TextureWrap::kClampToEdge;
    out.textures.push_back(texture);
    Material material;
    material.name = texture.name;
    material.base_color_texture = static_cast<int>(b);
    material.double_sided = false;
    out.materials.push_back(material);
    for (int t : buffer.triangles) {
      out.mesh.material[t] = static_cast<int>(b) + 1;
      out.mesh.has_uv[t] = true;
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector2d q = buffer.TexelCoords(mesh.Corner(t, k));
        out.mesh.uvs[t][k] = Eigen::Vector2f(static_cast<float>(q.x() / buffer.width),
                                             static_cast<float>(q.y() / buffer.height));
      }
    }
  }
  return out;
}

// The obvious implementation, for `fresco bench` to compare against: per frame a full
// depth render, then per buffer every texel projected one by one through the camera
// (Camera::Project), the depth compared, and the frame resampled with cv::remap.
void PaintSession::PaintFrameNaive(const Frame& frame, const Camera& camera,
                                   const Rigid3d& cam_from_world, FrameReport* report) {
  const auto start = std::chrono::steady_clock::now();
  report->frame = frame.index;
  report->name = frame.name;
  report->stages.clear();
  report->paint = PaintFigures();
  report->refine = RefineFigures();
  const Rigid3d cam_from_local = CamFromLocal(*scene_, cam_from_world);
  CacheFor(camera).rasterizer->RasterizeDepth(scene_->mesh, cam_from_local, &depth_);
  const float tolerance = static_cast<float>(options_.occlusion.tolerance_rel);
  PipelineOptions latest_wins;
  latest_wins.update = UpdatePolicy::kLatest;
  for (size_t b = 0; b < set_.buffers.size(); ++b) {
    const BaseBuffer& buffer = set_.buffers[b];
    cv::Mat map(buffer.height, buffer.width, CV_32FC2, cv::Scalar(-1, -1));
    WarpedBuffer& w = warped_[b];
    w.valid = cv::Mat::zeros(buffer.height, buffer.width, CV_8U);
    w.valid_box = cv::Rect(0, 0, buffer.width, buffer.height);
    w.quality = cv::Mat::ones(buffer.height, buffer.width, CV_32F);
    for (const BaseBuffer::Chunk& chunk : buffer.chunks)
      for (int k = chunk.begin; k < chunk.end; ++k) {
        const Eigen::Vector3d p = cam_from_local * buffer.PointIn(chunk, k).cast<double>();
        Eigen::Vector2d pixel;
        if (p.z() <= 0 || !camera.Project(p, &pixel)) continue;
        const int u = static_cast<int>(std::lround(pixel.x())),
                  v = static_cast<int>(std::lround(pixel.y()));
        if (u < 0 || v < 0 || u >= camera.width || v >= camera.height) continue;
        const float depth = depth_.at<float>(v, u);
        if (p.z() > depth * (1 + tolerance) + options_.occlusion.tolerance_m) continue;
        map.at<cv::Vec2f>(buffer.texel_index[k]) =
            cv::Vec2f(static_cast<float>(pixel.x()), static_cast<float>(pixel.y()));
        w.valid.data[buffer.texel_index[k]] = 255;
      }
    cv::remap(frame.bgr, w.bgr, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_CONSTANT);
    PaintBuffer(buffer, w, cv::Mat(), latest_wins, &painted_[b]);
  }
  StageReport all;
  all.name = "naive";
  all.wall_ms = MsSince(start);
  report->stages.push_back(std::move(all));
  report->painted = true;
  report->total_ms = all.wall_ms;
}

}  // namespace fresco
