#include "pipeline/paint/paint_session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/scaled_camera.h"
#include "pipeline/paint/charts.h"
#include "pipeline/paint/stage_clock.h"
#include "pipeline/render/renderer.h"

namespace fresco {
namespace {

bool SameCamera(const Camera& a, const Camera& b) {
  return a.width == b.width && a.height == b.height && a.Params() == b.Params() &&
         a.model == b.model;
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
  const Camera small =
      ScaledCamera(camera, std::max(1, camera.width / scale), std::max(1, camera.height / scale));
  std::vector<float> depths;
  try {
    const Rasterizer raster(small, RasterOptions());
    const size_t step = std::max<size_t>(1, cam_from_world.size() / 16);
    const int poses = static_cast<int>((cam_from_world.size() + step - 1) / step);
    // The poses at once (a small image's rasterizing is mostly on one core); the median does
    // not depend on the order the depths come in.
    std::vector<std::vector<float>> seen(poses);
    cv::parallel_for_(
        cv::Range(0, poses),
        [&](const cv::Range& range) {
          RasterOutput out;
          for (int k = range.start; k < range.end; ++k) {
            raster.Rasterize(scene.mesh, CamFromLocal(scene, cam_from_world[k * step]), &out);
            for (int y = 0; y < out.depth.rows; ++y)
              for (int x = 0; x < out.depth.cols; ++x)
                if (const float z = out.depth.at<float>(y, x); std::isfinite(z))
                  seen[k].push_back(z);
          }
          Rasterizer::ReleaseThreadScratch();  // see below
        },
        std::min(poses, cv::getNumThreads()));
    for (const std::vector<float>& d : seen) depths.insert(depths.end(), d.begin(), d.end());
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
  s->requested_update_ = inputs.pipeline.update;
  s->requested_background_ = inputs.pipeline.background.mode;
  s->expected_frames_ = static_cast<int>(inputs.expected_poses.size());
  if (inputs.pipeline.max_frames > 0)  // the run stops there
    s->expected_frames_ = std::min(s->expected_frames_, inputs.pipeline.max_frames);
  s->options_.background.warmup_frames = EffectiveWarmupFrames(inputs);
  const TriangleMesh& mesh = inputs.scene->mesh;
  if (mesh.NumTriangles() == 0) return Status::Error(inputs.scene->source_path + ": no triangles");
  s->texel_size_m_ =
      inputs.layout ? inputs.layout->texel_size_m
      : inputs.pipeline.texel_size_m > 0
          ? inputs.pipeline.texel_size_m
          : (inputs.typical_camera
                 ? AutomaticTexelSize(*inputs.scene, *inputs.typical_camera, inputs.expected_poses)
                 : 0.01);
  BaseBufferOptions& buffer_options = s->buffer_options_;
  buffer_options.texel_size_m = s->texel_size_m_;
  buffer_options.max_buffer_texels = inputs.pipeline.max_buffer_texels;
  buffer_options.max_side_texels = MaxBufferSide(inputs.pipeline.atlas);
  if (inputs.layout) {
    s->set_ = HollowBaseBuffers(mesh, *inputs.layout, buffer_options);
    s->hollow_.assign(s->set_.buffers.size(), true);
  } else {
    Grouping grouping;
    ChartScale chart_scale;
    chart_scale.texel_size_m = s->texel_size_m_;
    chart_scale.max_chart_texels = inputs.pipeline.max_buffer_texels;
    FRESCO_RETURN_IF_ERROR(MakeGrouping(mesh, inputs.grouping, chart_scale, &grouping));
    buffer_options.layout_only = inputs.layout_only;
    s->set_ = BuildBaseBuffers(mesh, grouping, buffer_options);
    buffer_options.layout_only = false;
    if (inputs.layout_only) s->hollow_.assign(s->set_.buffers.size(), true);
  }
  std::vector<cv::Size> sizes;
  for (const BaseBuffer& b : s->set_.buffers) sizes.emplace_back(b.width, b.height);
  FRESCO_RETURN_IF_ERROR(PackAtlas(sizes, inputs.pipeline.atlas, &s->atlas_));
  s->painted_.resize(s->set_.buffers.size());
  s->anchors_.resize(s->set_.buffers.size());
  s->warped_.resize(s->set_.buffers.size());
  for (size_t b = 0; b < s->set_.buffers.size(); ++b) {
    if (!s->BufferBuilt(b)) continue;
    InitRefineAnchor(s->set_.buffers[b], &s->anchors_[b]);
    InitPaintedBuffer(s->set_.buffers[b], &s->painted_[b]);
  }
  Eigen::Vector3d lo, hi;
  inputs.scene->Bounds(&lo, &hi);
  s->scene_centre_ = 0.5 * (lo + hi);
  s->StartAutoModes();
  *session = std::move(s);
  return Status::Ok();
}

void PaintSession::ResetPainting() {
  for (size_t b = 0; b < set_.buffers.size(); ++b) {
    if (!BufferBuilt(b)) continue;
    InitPaintedBuffer(set_.buffers[b], &painted_[b]);
    InitRefineAnchor(set_.buffers[b], &anchors_[b]);
  }
  layers_.clear();
  frames_seen_ = 0;
  StartAutoModes();
  own_only_.store(false);
  UpdateOwnOnly();
  exposure_gain_sum_ = exposure_offset_sum_ = cv::Vec3d(0, 0, 0);
  exposure_frames_ = 0;
}

void PaintSession::StartAutoModes() {
  options_.update = requested_update_;
  update_auto_ = AutoDecision();
  update_held_out_.clear();
  model_decided_early_ = false;
  if (requested_update_ == UpdatePolicy::kAuto) {
    update_auto_.basis = "held_out";
    update_auto_.threshold = 0;
    update_auto_.state = AutoDecision::State::kDeciding;
    // View selection keeps views by its own score; refinement registers each frame to the
    // buffers, which must stay the sharpest views (the mean of misregistered views blurs them).
    // The background model on by hand: the mean would take in what it lets through.
    const bool refine_on =
        requested_refine_ != RefineMode::kOff && requested_refine_ != RefineMode::kAuto;
    const bool model_on = requested_background_ != BackgroundMode::kOff &&
                          requested_background_ != BackgroundMode::kAuto;
    if (refine_on) KeepSharpestViews("refinement_on");
    else if (model_on) KeepSharpestViews("background_model_on");
    else if (options_.select.enabled) KeepSharpestViews("view_selection");
  }
  const bool refine_auto = requested_refine_ == RefineMode::kAuto;
  const bool background_auto = requested_background_ == BackgroundMode::kAuto;
  options_.refine.mode = refine_auto ? RefineMode::kRobust : requested_refine_;
  options_.background.mode = background_auto ? BackgroundMode::kRobust : requested_background_;
  refine_auto_.Start(refine_auto);
  background_auto_.Start(background_auto, options_.background.warmup_frames, expected_frames_);
  if (background_auto && background_across_views_.second >= 0) {
    background_auto_.DecideAcrossViews(background_across_views_.first,
                                       background_across_views_.second);
    if (background_auto_.decision().state == AutoDecision::State::kOff)
      options_.background.mode = BackgroundMode::kOff;
  }
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

void PaintSession::DecideBackgroundAcrossViews(double fraction, int frames) {
  background_across_views_ = {fraction, frames};
  if (!background_auto_.deciding()) return;
  background_auto_.DecideAcrossViews(fraction, frames);
  if (background_auto_.decision().state == AutoDecision::State::kOff) {
    options_.background.mode = BackgroundMode::kOff;
    background_.clear();
    background_frame_.clear();
  }
  UpdateOwnOnly();
}

void PaintSession::SetRefinePoseCheck(double ratio, double threshold, int frames) {
  refine_auto_.SetPoseCheck(ratio, threshold, frames);
}

void PaintSession::SetOwnBuffers(std::vector<bool> own) {
  if (!own.empty() && own.size() != set_.buffers.size())
    throw std::invalid_argument("PaintSession::SetOwnBuffers: " + std::to_string(own.size()) +
                                " flags for " + std::to_string(set_.buffers.size()) + " buffers");
  own_ = std::move(own);
  own_only_.store(false);
  UpdateOwnOnly();
  BuildPaintedBuffers();
}

void PaintSession::BuildPaintedBuffers() {
  for (size_t b = 0; b < hollow_.size(); ++b) {
    if (!hollow_[b] || (own_only_.load() && !own_.empty() && !own_[b])) continue;
    set_.buffers[b] = BuildLaidOutBuffer(scene_->mesh, set_, b, buffer_options_);
    hollow_[b] = false;
    InitRefineAnchor(set_.buffers[b], &anchors_[b]);
    InitPaintedBuffer(set_.buffers[b], &painted_[b]);
    for (std::vector<BufferBackground>& models : background_)
      if (b < models.size()) models[b].Init(set_.buffers[b], options_.background);
  }
}

BufferLayout PaintSession::Layout() const {
  BufferLayout layout;
  layout.texel_size_m = texel_size_m_;
  layout.folds_split = set_.folds_split;
  layout.recipes = set_.recipes;
  return layout;
}

bool PaintSession::CouplesBuffers() const {
  return DecidingUpdate() || refine_auto_.deciding() || background_auto_.deciding() ||
         options_.refine.mode != RefineMode::kOff || SelectActive(options_) ||
         options_.layers.count > 0 ||
         (options_.background.mode == BackgroundMode::kRobust &&
          options_.background.normalize_gain);
}

FrameView PaintSession::BoundsView(const Camera& camera, const NormalizedBounds& bounds,
                                   const Rigid3d& cam_from_world) const {
  FrameView view;
  view.camera = &camera;
  view.cam_from_local = CamFromLocal(*scene_, cam_from_world);
  view.centre_local = view.cam_from_local.Centre();
  view.bounds = bounds;
  return view;
}

bool PaintSession::ViewMeetsOwnBuffers(const Camera& camera, const NormalizedBounds& bounds,
                                       const Rigid3d& cam_from_world) const {
  const FrameView view = BoundsView(camera, bounds, cam_from_world);
  const double near_m = WarpOptions().near_m;
  for (size_t b = 0; b < set_.buffers.size(); ++b)
    if ((own_.empty() || own_[b]) &&
        !BoundsOutsideView(set_.buffers[b].bounds_min, set_.buffers[b].bounds_max, view, near_m))
      return true;
  return false;
}

void PaintSession::BufferBoxesInView(
    const Camera& camera, const NormalizedBounds& bounds, const Rigid3d& cam_from_world,
    std::vector<std::optional<std::array<float, 4>>>* boxes) const {
  const FrameView view = BoundsView(camera, bounds, cam_from_world);
  const double near_m = WarpOptions().near_m;
  for (size_t b = 0; b < set_.buffers.size(); ++b) {
    (*boxes)[b].reset();
    if (BoundsOutsideView(set_.buffers[b].bounds_min, set_.buffers[b].bounds_max, view, near_m))
      continue;
    const double inf = std::numeric_limits<double>::infinity();
    double box[4] = {inf, inf, -inf, -inf};
    std::array<float, 4> share = {0, 0, 1, 1};
    if (BufferImageBox(b, view, box) && box[0] <= box[2])
      for (int i = 0; i < 4; ++i)
        share[i] = static_cast<float>(
            std::clamp(box[i] / (i % 2 ? camera.height : camera.width), 0.0, 1.0));
    (*boxes)[b] = share;
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
      // The model's own verdict: growth spreads whatever was flagged (thin edges of a
      // high-frequency texture seen at another resolution too), so it is no evidence.
      masked += background_frame_[b].masked_ungrown;
    }
    if (background_auto_.AddFrame(frame_number, observed, warming, masked) &&
        background_auto_.decision().state == AutoDecision::State::kOff) {
      options_.background.mode = BackgroundMode::kOff;  // painting continues as `off`
      background_.clear();
      background_frame_.clear();
      // What the model left provisional is kept by its quality from now on, as in `off`
      // (provisional, any later sample would replace it, however blurred).
      for (PaintedBuffer& painted : painted_) cv::absdiff(painted.quality, 0, painted.quality);
    }
  }
  report->decisions = auto_decisions();
  if (StageReport* refine = report->Stage("refine")) report->decisions.refine.PutInto(refine);
  if (StageReport* background = report->Stage("background"))
    report->decisions.background.PutInto(background);
  if (StageReport* paint = report->Stage("paint")) report->decisions.update.PutInto(paint);
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

namespace {

// PaintFrame's precondition: the frame is 8-bit BGR of its camera's size, since its pixels
// are read through the camera's rays. The frame policy (pipeline/run/frame_policy.h) keeps
// other frames out with a message naming them; a caller that reaches here without it is a
// defect: an internal error (exit 1), never a read out of bounds.
void CheckFrameFitsCamera(const Frame& frame, const Camera& camera) {
  if (frame.bgr.cols == camera.width && frame.bgr.rows == camera.height &&
      frame.bgr.type() == CV_8UC3)
    return;
  throw std::logic_error("PaintFrame: frame '" + frame.name + "' is " +
                         std::to_string(frame.bgr.cols) + "x" + std::to_string(frame.bgr.rows) +
                         " with " + std::to_string(frame.bgr.channels()) +
                         " channels, but its camera is " + std::to_string(camera.width) + "x" +
                         std::to_string(camera.height) + " BGR (the frame policy was not applied)");
}

}  // namespace

void PaintSession::PaintFrame(const Frame& frame, const Camera& camera,
                              const Rigid3d& cam_from_world, int stream, FrameReport* report) {
  CheckFrameFitsCamera(frame, camera);
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
  FrameWork work;
  work.frame = &frame;
  work.camera = &camera;
  work.cam_from_local = CamFromLocal(*scene_, cam_from_world);
  work.stream = stream;
  work.number = frame_number;
  work.debug = options_.debug_images;
  work.report = report;
  // `update: auto`'s frames held out of the comparison: with the capture's length known, spread
  // over the whole capture, the choice made as it nears its end (early on the mean holds few,
  // near views, and movers that linger are where the held-out frames' own movers hide them:
  // on the suites the first 24 frames chose the mean, or the model off, where the whole
  // capture is better without); else (live) every 4th of the first 24 frames.
  const int hold_every =
      expected_frames_ > 0
          ? std::max(kUpdateHoldOutEvery, expected_frames_ / (kUpdateHeldOutFrames + 1))
          : kUpdateHoldOutEvery;
  work.held_out = DecidingUpdate() && frame_number % hold_every == hold_every / 2 &&
                  update_held_out_.size() < static_cast<size_t>(kUpdateHeldOutFrames);
  if (work.held_out)
    update_held_out_.push_back({frame.bgr.clone(), frame.movers.clone(), camera, cam_from_world});
#define FRESCO_RUN_STAGE(Name) Name##Stage(&work);
  FRESCO_PAINT_STAGES(FRESCO_RUN_STAGE)
#undef FRESCO_RUN_STAGE
  if (frame_number + 1 >= hold_every * kModelHeldOutFrames) DecideModelEarly();
  if (frame_number + 1 >= hold_every * kUpdateHeldOutFrames) DecideUpdate();
  UpdateAutoModes(frame_number, work.measured_misalignment_px, work.seen, report);
  if (!own_.empty() && !own_only_.load()) ++frames_painted_whole_;
  UpdateOwnOnly();
  report->painted = true;
  report->total_ms = MsSince(frame_start);
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

Scene PaintSession::PaintedScene() const { return PaintedScene(false); }

Scene PaintSession::PaintedSceneOfOwnBuffers(bool geometry) const {
  return PaintedScene(true, geometry);
}

Scene PaintSession::PaintedScene(const std::vector<cv::Mat>& buffer_bgra) const {
  return PaintedScene(buffer_bgra, false);
}

cv::Mat PaintSession::PageImage(int page, const std::vector<cv::Mat>& images, bool own_only) const {
  if (!own_only) return ComposeAtlasPage(atlas_, page, images);
  std::vector<bool> own = own_;
  if (own.empty()) own.assign(images.size(), true);
  return ComposeAtlasStrip(atlas_, page, images, own);
}

Scene PaintSession::PaintedScene(bool own_only, bool geometry) const {
  std::vector<cv::Mat> images(painted_.size());
  for (size_t b = 0; b < painted_.size(); ++b)
    if (!own_only || own_.empty() || own_[b]) images[b] = AtMeanExposure(painted_[b].bgra);
  Scene scene = PaintedScene(images, own_only, geometry);
  // Each layer's pages after the base pages; material page + 1 shows page `page`.
  for (const ViewLayer& layer : layers_) {
    ViewLayerTextures textures;
    textures.centre_world = scene_->WorldFromLocal(layer.Centre());
    textures.material_texture.assign(scene.materials.size(), -1);
    for (size_t b = 0; b < images.size(); ++b)
      if (!own_only || own_.empty() || own_[b]) images[b] = AtMeanExposure(layer.painted[b].bgra);
    for (size_t page = 0; page < atlas_.pages.size(); ++page) {
      Texture texture;
      texture.name =
          "layer_" + std::to_string(scene.view_layers.size()) + "_page_" + std::to_string(page);
      cv::cvtColor(PageImage(static_cast<int>(page), images, own_only), texture.rgba,
                   cv::COLOR_BGRA2RGBA);
      texture.wrap_s = texture.wrap_t = TextureWrap::kClampToEdge;
      if (geometry) textures.material_texture[page + 1] = static_cast<int>(scene.textures.size());
      scene.textures.push_back(std::move(texture));
    }
    scene.view_layers.push_back(std::move(textures));
  }
  return scene;
}

Scene PaintSession::PaintedScene(const std::vector<cv::Mat>& buffer_bgra, bool own_only,
                                 bool geometry) const {
  Scene out;
  if (geometry) out = UnpaintedCopy(*scene_);
  const TriangleMesh& mesh = scene_->mesh;
  for (size_t page = 0; page < atlas_.pages.size(); ++page) {
    Texture texture;
    texture.name = "page_" + std::to_string(page);
    cv::cvtColor(PageImage(static_cast<int>(page), buffer_bgra, own_only), texture.rgba,
                 cv::COLOR_BGRA2RGBA);
    texture.wrap_s = texture.wrap_t = TextureWrap::kClampToEdge;
    out.textures.push_back(texture);
    if (!geometry) continue;
    Material material;
    material.name = texture.name;
    material.base_color_texture = static_cast<int>(page);
    out.materials.push_back(material);
  }
  for (size_t b = 0; geometry && b < set_.buffers.size(); ++b) {
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
  CheckFrameFitsCamera(frame, camera);
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
