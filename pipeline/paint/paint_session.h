// The painting pipeline, stage by stage, behind one facade. Stages in order, per frame (the
// list is paint_stages.h; each stage in its own file):
//   1. depth   render the model's depth from the video camera (§3.3)     -> depth_stage.cc
//   2. warp    per texel: project, reject grazing/back-facing, occlusion test, sample
//              (eq. 1-4, §3.2, §3.3)                      -> warp_stage.cc, frame_warp.h
//   3. refine  per buffer: register the warped frame to what the buffer holds in 2D and
//              warp it again (§3.5; pipeline.refine.mode) -> refine_stage.cc, refine_alignment.h
//   3b. exposure  divide out the frame's gain against the buffers (pipeline.select.exposure)
//                                                      -> select_stages.cc, exposure_gain.h
//   4. background  per texel: compare with the texel's background model, mask foreground
//              (moving objects), learn (§3.4)     -> background_stage.cc, background_model.h
//   4b. select  view score per texel (resolution, angle, depth edges); painted texels keep
//              a better stored sample (pipeline.select)  -> select_stages.cc, view_select.h
//   5. paint   update the persistent base buffers where not masked (eq. 4, update policy)
//                                                         -> paint_stage.cc, paint_update.h
// Set-up (once): grouping (§3.6) -> grouping.h, base buffers and texel model points (eq. 2)
// -> base_buffer.h. Each stage reports wall time, metrics and (when asked) debug images in a
// FrameReport that the CLI and the GUI both consume.
#pragma once

#include <array>
#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/core/camera.h"
#include "pipeline/core/project.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/scene.h"
#include "pipeline/core/video_source.h"
#include "pipeline/paint/auto_modes.h"
#include "pipeline/paint/background_model.h"
#include "pipeline/paint/base_buffer.h"
#include "pipeline/paint/frame_warp.h"
#include "pipeline/paint/paint_stages.h"
#include "pipeline/paint/paint_update.h"
#include "pipeline/paint/refine_alignment.h"
#include "pipeline/paint/refine_anchor.h"
#include "pipeline/paint/refine_pose.h"
#include "pipeline/paint/stage_report.h"
#include "pipeline/paint/texture_atlas.h"
#include "pipeline/paint/view_layers.h"
#include "pipeline/render/rasterizer.h"

namespace fresco {

struct PaintSessionInputs {
  const Scene* scene = nullptr;
  PipelineOptions pipeline;
  GroupingOptions grouping;
  // Poses (cam_from_world) and cameras the video will bring, used only to choose the
  // automatic texel size (about one texel per pixel at the typical distance).
  std::vector<Rigid3d> expected_poses;
  const Camera* typical_camera = nullptr;
  // Non-null: the buffers laid out as this layout says (its texel size and charts, as another
  // session over the same scene and settings laid them out: PaintSession::Layout), built
  // hollow, without texels: SetOwnBuffers builds those the session will paint.
  const BufferLayout* layout = nullptr;
  // True: the buffers are laid out only (BaseBufferOptions::layout_only), hollow: a session
  // that only finds the layout (PaintSession::Layout) and paints nothing.
  bool layout_only = false;
};

// One frame on its way through the stages (paint_stages.h): what they hand each other.
struct FrameWork {
  const Frame* frame = nullptr;
  const Camera* camera = nullptr;
  Rigid3d cam_from_local;
  int stream = 0;
  int number = 0;      // frames this session saw before this one
  bool debug = false;  // debug images asked
  FrameReport* report = nullptr;
  // From the warp stage on: the view, the buffers in the frustum, the buffers seen (some
  // texel visible), whether the warp painted them itself (no stage between them looks at
  // the samples), and each buffer's paint statistics.
  FrameView view;
  std::vector<size_t> in_frustum;
  std::vector<bool> seen;
  bool paint_in_warp = false;
  bool held_out = false;  // update `auto` deciding: held out of the decision's shadows
  std::vector<PaintUpdateStats> paint_stats;
  // refine.mode auto, deciding: the misalignment a correction would remove this frame,
  // measured by refinement (< 0: none).
  double measured_misalignment_px = -1;
};

class PaintSession {
 public:
  // Groups the mesh, builds the base buffers. Errors name the grouping edit or setting.
  static Status Create(const PaintSessionInputs& inputs, std::unique_ptr<PaintSession>* session);

  // Builds what painting through `camera` needs once (its depth rasterizer's ray table and
  // the mesh's culling clusters, its frustum bounds), so that the first frame through it
  // costs what the others do. Optional: PaintFrame builds it on first use.
  void PrepareCamera(const Camera& camera) { CacheFor(camera).rasterizer->Prepare(scene_->mesh); }

  // Paints one frame seen from `cam_from_world` through `camera`. Fills `report`.
  // `stream`: the video stream it comes from (index into Project::Streams()); the background
  // stage classifies it against that stream's own models (stream 0's made with the session,
  // another stream's when its first frame reaches the stage), so that cameras of different
  // sharpness or colour do not take each other's samples for foreground. Without it: stream 0.
  void PaintFrame(const Frame& frame, const Camera& camera, const Rigid3d& cam_from_world,
                  int stream, FrameReport* report);
  void PaintFrame(const Frame& frame, const Camera& camera, const Rigid3d& cam_from_world,
                  FrameReport* report) {
    PaintFrame(frame, camera, cam_from_world, 0, report);
  }

  // The naive baseline `fresco bench` measures against (paints the same buffers): full
  // depth render, every texel projected one at a time, cv::remap per buffer, latest wins.
  void PaintFrameNaive(const Frame& frame, const Camera& camera, const Rigid3d& cam_from_world,
                       FrameReport* report);

  // Forgets everything painted (buffers, background models, anchors, frame count); the
  // grouping, buffers' layout and camera caches stay (time_offset_estimation.h repaints
  // the same frames once per candidate offset).
  void ResetPainting();

  // Everything painting changes (painting_state.h: the buffers, the per-texel models, the
  // layers, the `auto` modes' decisions and evidence so far, the frame counts), saved between
  // two frames and restored: painting on from a restored state gives, byte for byte, what
  // painting on from where it was saved gave (the app steps back from its nearest saved state
  // instead of repainting from the first frame). A state fits the session that saved it.
  // A state shares the image blocks it has in common with the one saved before it, while that
  // is held (painting_state.h).
  struct State;
  std::shared_ptr<const State> SaveState() const;
  void RestoreState(const State& state);

  // The scene's geometry with the painted buffers packed into texture atlas pages
  // (texture_atlas.h), one base-colour texture and material per page (alpha 0 where never
  // painted), and new UVs into them: what `fresco run` writes. With view-dependent layers
  // (pipeline.layers), each layer's pages too (Scene::view_layers).
  Scene PaintedScene() const;
  // The same with other images in the buffers' places (one CV_8UC4 BGRA image per buffer, of
  // its size): e.g. a mask of the texels that show something, rendered in any view.
  Scene PaintedScene(const std::vector<cv::Mat>& buffer_bgra) const;
  // The same with one texture and material per buffer (material b + 1 = buffer b, material 0
  // for triangles in no buffer): the per-buffer view the app and debug images use.
  Scene PaintedSceneByBuffer() const;
  // PaintedScene() as a shard's part holds it (SetOwnBuffers): each texture holds, instead of
  // its page, the own buffers' padded placements on that page (ComposeAtlasStrip), which
  // `fresco merge` puts back in place; the rest (mesh, UVs, materials) as PaintedScene()'s.
  // Without `geometry` only the textures (the mesh empty, no materials): the pages of a part
  // whose glTF another part writes.
  Scene PaintedSceneOfOwnBuffers(bool geometry = true) const;
  const TextureAtlas& atlas() const { return atlas_; }
  // The view-dependent layers (pipeline.layers; view_layers.h) as they are painted; in
  // PaintedScene() they follow the base pages as textures of their own (Scene::view_layers).
  const std::vector<ViewLayer>& view_layers() const { return layers_; }

  // Debug images on or off from the next frame on (the app asks only for frames it shows).
  void set_debug_images(bool on) { options_.debug_images = on; }
  // The options in force: `auto` modes show what they resolved to so far (refine.mode
  // robust or off, background.mode robust or off; robust while deciding).
  const PipelineOptions& options() const { return options_; }
  // What the `auto` modes decided so far, and on what evidence (auto_modes.h).
  // background.mode auto, before the first frame: decides from the movers found across views
  // (`fraction` of the pixels judged over `frames` frames masked; mover_masks.h) instead of
  // frame by frame. Kept through ResetPainting.
  void DecideBackgroundAcrossViews(double fraction, int frames);
  // refine.mode auto, before the first frame: the joint pose adjustment's check (frames left
  // out of the corrections agree `ratio` times better with the corrected frames, over
  // `frames` frames), which below `threshold` keeps refinement off
  // (RefineAutoDecider::SetPoseCheck). Kept through ResetPainting.
  void SetRefinePoseCheck(double ratio, double threshold, int frames);
  AutoDecisions auto_decisions() const {
    return {refine_auto_.decision(), background_auto_.decision(), update_auto_};
  }
  // `update: auto` (pipeline_options.h): until decided, every texel keeps the sharpest view
  // (as `quality`) and the sums of every view (as `mean`; with the background model that
  // `auto` turned on, also without its mask), and the same without 6 frames held out of the
  // decision (painted as every frame): spread over the capture when its length is known
  // (every N / 7-th frame, at least every 4th), else frames 2, 6, ..., 22. After the 6th, or at
  // the end of a shorter capture (the job's frame loop calls DecideUpdate there), the model painted
  // each way without the held-out frames is rendered at their poses and compared with them (PSNR
  // over the pixels every way paints, less the movers found across views); the way that
  // agrees better paints on, from what every frame painted. With the background model on by
  // hand, refinement on (it registers frames to the sharpest views) or view selection:
  // `quality`, as without frames compared.
  static constexpr int kUpdateHoldOutEvery = 4;
  static constexpr int kUpdateHeldOutFrames = 6;
  // `update: auto` takes the sharp mean only where it beats the mean by this much a frame held
  // out (DecideUpdate).
  static constexpr double kSharpMeanMarginDb = 0.1;
  bool DecidingUpdate() const { return update_auto_.state == AutoDecision::State::kDeciding; }
  void DecideUpdate();
  // With background `auto`'s model on while the update decides, the model is judged first on
  // the first half of the frames held out (kModelHeldOutFrames, as soon as they are in): the
  // mean without the model scoring above the mean with it and the sharpest view turns the model
  // off from then on (what it would cost for the rest of the capture is saved; the update still
  // decides on all of them). Else the choice waits for the update's, as before.
  static constexpr int kModelHeldOutFrames = 3;
  bool DecidingModelOnHeldOut() const;
  void DecideModelEarly();

  // Painting in shards (`fresco run --shard I/N`, pipeline/run/shard.h): `own[b]` true for
  // the buffers this session paints for its shard (empty: every buffer, the default). The
  // session still paints every buffer a frame sees while a frame's outcome in one buffer
  // depends on the others (CouplesBuffers): so the shards' buffers come out exactly as one
  // session over every buffer paints them.
  // A session made from a layout (PaintSessionInputs::layout) builds here the texels and
  // painted images of the buffers it will paint: the own ones when no buffer is coupled
  // (PaintsOwnBuffersOnly), else every buffer; the others stay hollow (no texels, nothing
  // painted, left out of the atlas pages).
  void SetOwnBuffers(std::vector<bool> own);
  // The buffers' layout (texel size, charts, each buffer's recipe): what a session made with
  // PaintSessionInputs::layout takes to lay out the same buffers without building them.
  BufferLayout Layout() const;
  // Whether buffer b has its texels (false: hollow, PaintSessionInputs::layout).
  bool BufferBuilt(size_t b) const { return hollow_.empty() || !hollow_[b]; }
  // True while painting one buffer depends on the frame's other buffers: an `auto` mode
  // deciding (its evidence spans the frame), refinement on (one pose correction from every
  // buffer's matches), view selection (one exposure gain per frame), view-dependent layers
  // (a frame's layer depends on every frame before it), the background model dividing out
  // the frame's gain (one gain over every buffer seen).
  bool CouplesBuffers() const;
  // Own buffers set and none coupled: frames paint only the own buffers, and a frame whose
  // view meets none of them may be skipped (SkipFrame) without being read. Once true, stays
  // true. Safe to read from another thread (a source reading ahead).
  bool PaintsOwnBuffersOnly() const { return own_only_.load(); }
  // Whether the view of `camera` at `cam_from_world` meets the bounds of some own buffer
  // (every buffer when none set): the frustum test of the warp stage. `bounds`:
  // ComputeNormalizedBounds(camera). Const, for a source reading ahead.
  bool ViewMeetsOwnBuffers(const Camera& camera, const NormalizedBounds& bounds,
                           const Rigid3d& cam_from_world) const;
  // For every buffer b whose bounds the view meets (the same test; boxes has one entry per
  // buffer; the others get none): its BufferImageBox as a share of the image, clipped to it
  // ({x0, y0, x1, y1} in 0..1; the whole image when not bounded by it), in (*boxes)[b]. How
  // many frames see each buffer, and where, which shards balance.
  void BufferBoxesInView(const Camera& camera, const NormalizedBounds& bounds,
                         const Rigid3d& cam_from_world,
                         std::vector<std::optional<std::array<float, 4>>>* boxes) const;
  // Widens `box` ({x0, y0, x1, y1} in pixels) by the image of buffer b's bounds' part in front
  // of the camera (the warp tests no texel nearer than its near plane: the bounds are cut at
  // half of it, their corners there and where their edges cross it); false when that image is
  // not bounded by it (a lens with distortion).
  bool BufferImageBox(size_t b, const FrameView& view, double box[4]) const;
  // A frame the source skipped (PaintsOwnBuffersOnly, its view meets no own buffer): counted
  // as painted frames are (the frame numbers the stages and `update_every` use) and nothing
  // else; painting it would have changed no own buffer.
  void SkipFrame() { ++frames_seen_; }
  // Frames painted over every buffer they see while own buffers were set (CouplesBuffers).
  int frames_painted_whole() const { return frames_painted_whole_; }
  const std::vector<bool>& own_buffers() const { return own_; }

  const std::vector<BaseBuffer>& buffers() const { return set_.buffers; }
  const std::vector<PaintedBuffer>& painted() const { return painted_; }
  // The texels of buffer b that the last frame's background stage kept out of painting
  // (CV_8U, 255, the buffer's size), for a buffer that frame saw; empty where it kept none
  // out or the background model is off.
  cv::Mat KeptOutOfPainting(size_t b) const;
  const std::vector<RefineAnchor>& anchors() const { return anchors_; }
  const Grouping& grouping() const { return set_.grouping; }
  int folds_split() const { return set_.folds_split; }
  long long NumSurfaceTexels() const;
  long long NumPaintedSurfaceTexels() const;
  double Coverage() const;
  double default_texel_size_m() const { return texel_size_m_; }
  // The background model's current estimate of buffer `b` as stream `stream` learned it
  // (CV_8UC3; empty when off or when that stream has painted no frame yet).
  cv::Mat BackgroundImage(size_t b, int stream = 0) const;

 private:
  void KeepSharpestViews(const char* why);
  // PaintedScene(), its pages whole or (own_only) the own buffers' placements only; without
  // `geometry` only its textures.
  Scene PaintedScene(bool own_only, bool geometry = true) const;
  Scene PaintedScene(const std::vector<cv::Mat>& buffer_bgra, bool own_only,
                     bool geometry = true) const;
  cv::Mat PageImage(int page, const std::vector<cv::Mat>& images,
                    bool own_only) const;  // DecideUpdate: `quality`, for the reason given
  PaintSession() = default;
  // The stages, one member each (paint_stages.h): `void DepthStage(FrameWork*)`, ...
#define FRESCO_DECLARE_STAGE(Name) void Name##Stage(FrameWork* work);
  FRESCO_PAINT_STAGES(FRESCO_DECLARE_STAGE)
#undef FRESCO_DECLARE_STAGE
  // Where the depth stage's map is read (depth_stage.cc); empty: the whole image.
  cv::Rect OwnBuffersWindow(const Camera& camera, const NormalizedBounds& bounds,
                            const Rigid3d& cam_from_local) const;
  // Per distinct camera: its depth rasterizer and its frustum bounds (built once).
  struct CameraCache {
    Camera camera;
    std::unique_ptr<Rasterizer> rasterizer;
    NormalizedBounds bounds;
  };
  const CameraCache& CacheFor(const Camera& camera);
  // Runs fn(b) for every buffer in `todo` (each b at most once, buffers independent): large
  // buffers one after the other (each runs in parallel inside), the many small ones of a
  // charted photogrammetry mesh spread over the threads. `serial`: all in order.
  void ForEachBuffer(const std::vector<size_t>& todo, bool serial,
                     const std::function<void(size_t)>& fn) const;
  // The refinement stage over the buffers seen this frame (re-warps warped_); its typed
  // figures go to `figures` too.
  // `measure_only` (refine.mode auto, deciding): registers and measures the misalignment
  // but corrects nothing.
  StageReport RefineAlignment(const std::vector<bool>& seen, bool debug, bool measure_only,
                              RefineFigures* figures);
  // (Re)starts the `auto` modes: what they run while deciding, and their deciders.
  void StartAutoModes();
  // Feeds this frame's evidence (misalignment_px: measured by refinement this frame, texels;
  // < 0 none) to the deciders, applies a decision taken and shows the state in `report`.
  void UpdateAutoModes(int frame_number, double misalignment_px, const std::vector<bool>& seen,
                       FrameReport* report);
  struct BufferRefinement;
  // Clears the frame's valid texels of buffer `b` (within `roi`) where the buffer is painted.
  void KeepOutOfPainted(size_t b, const cv::Rect& roi);
  // Registers the frame's warped buffer `b` to what it holds (fills result->estimate).
  void EstimateBuffer(size_t b, bool debug, BufferRefinement* result);
  // Applies the estimate: warps again, anchors, keeps unregistered misaligned frames out.
  void FinishBuffer(size_t b, bool debug, BufferRefinement* result);
  // Replaces the buffers' estimates by what one correction of the frame's pose implies
  // (refine_pose.h); `fresh`: buffers seen but never painted, which get it too.
  void CorrectThroughPose(const std::vector<size_t>& todo, const std::vector<size_t>& fresh,
                          bool measure_only, std::vector<BufferRefinement>* results,
                          StageReport* report);
  // The background stage over the buffers seen this frame, against stream `stream`'s models
  // (fills background_frame_ and `figures`).
  // `movers`: the frame's Frame::movers (or empty), warped through `view` (the frame's); where
  // they touch the foreground the model flags in a buffer, they join it. `first_frames`: one
  // of the session's first frames (background_stage.cc).
  StageReport SegmentForeground(const std::vector<bool>& seen, int stream, bool debug,
                                const cv::Mat& movers, const FrameView* view, bool first_frames,
                                BackgroundFigures* figures);
  // The frame's movers found across views (`movers`, mover_masks.h) warped into the buffers
  // seen as the frame was: mover_texels_ (255 where they cover a texel seen) and
  // agreed_texels_ (255 where the pixels the frames near it agree with do), and
  // near_mover_texels_ (255 within background.mover_margin of a mover, not a mover's).
  void WarpMovers(const std::vector<size_t>& seen_list, const cv::Mat& movers,
                  const FrameView& view);
  // Stream `stream`'s background models, one per buffer, initialized on first use.
  std::vector<BufferBackground>& StreamBackground(int stream);
  // The exposure and select stages (select_stages.cc) over the buffers seen this frame.
  StageReport CorrectExposure(const std::vector<size_t>& seen);
  StageReport SelectViewsStage(const std::vector<size_t>& seen);
  // A painted buffer (BGRA) at the frames' mean exposure: the buffers hold the first
  // frames' exposure (exposure stage); the painted scene takes the mean of every painted
  // frame's transform (select_stages.cc). The buffer itself when the stage is off.
  cv::Mat AtMeanExposure(const cv::Mat& bgra) const;

  // The view ViewMeetsOwnBuffers and BufferBoxesInView test the buffers' bounds against.
  FrameView BoundsView(const Camera& camera, const NormalizedBounds& bounds,
                       const Rigid3d& cam_from_world) const;
  // Sharded painting (SetOwnBuffers): the own buffers, and whether only they are painted.
  void UpdateOwnOnly() { own_only_.store(own_only_.load() || (!own_.empty() && !CouplesBuffers())); }
  std::vector<bool> own_;
  std::atomic<bool> own_only_{false};
  mutable std::weak_ptr<const State> last_saved_;  // SaveState's last, to share blocks with
  std::vector<bool> hollow_;  // buffers without texels (empty: none)
  BaseBufferOptions buffer_options_;
  // Builds the hollow buffers the session paints (SetOwnBuffers).
  void BuildPaintedBuffers();
  int frames_painted_whole_ = 0;
  const Scene* scene_ = nullptr;
  PipelineOptions options_;
  RefineMode requested_refine_ = RefineMode::kOff;  // as given (auto resolves in options_)
  UpdatePolicy requested_update_ = UpdatePolicy::kQuality;  // likewise
  AutoDecision update_auto_;  // on: `mean`, off: `quality`
  struct HeldOutFrame {
    cv::Mat bgr, movers;
    Camera camera;
    Rigid3d cam_from_world;
  };
  std::vector<HeldOutFrame> update_held_out_;
  bool model_decided_early_ = false;  // DecideModelEarly ran
  // The candidates (the sharpest view, the mean, the mean without the model: the first `n`)
  // without the frames held out, scored at those frames (PSNR summed into `psnr_sum`);
  // returns the frames measured.
  int ScoreHeldOut(size_t n, std::vector<double>* psnr_sum,
                   const std::vector<int>& candidates = {}) const;
  void TurnModelOffByFramesHeldOut(double gain_db, int measured);
  BackgroundMode requested_background_ = BackgroundMode::kOff;
  // DecideBackgroundAcrossViews' evidence (fraction, frames); frames < 0: none.
  std::pair<double, int> background_across_views_{0.0, -1};
  int expected_frames_ = 0;  // the poses the inputs promised (0: unknown)
  RefineAutoDecider refine_auto_;
  BackgroundAutoDecider background_auto_;
  double texel_size_m_ = 0.0;
  BaseBufferSet set_;
  TextureAtlas atlas_;  // where each buffer goes in PaintedScene()
  std::vector<PaintedBuffer> painted_;
  std::vector<WarpedBuffer> warped_;
  // The frame's movers found across views (Frame::movers) warped into each buffer (WarpMovers).
  std::vector<WarpedBuffer> movers_warped_;
  std::vector<cv::Mat> mover_texels_, agreed_texels_, near_mover_texels_;
  std::vector<RefineAnchor> anchors_;                       // per buffer (refinement on)
  std::vector<ViewLayer> layers_;                           // pipeline.layers (layers_stage.cc)
  Eigen::Vector3d scene_centre_ = Eigen::Vector3d::Zero();  // the mesh's box centre (local)
  // Per stream, per buffer (mode != off): the background models. A stream's set is empty
  // until its first frame reaches the background stage (stream 0's is made up front).
  std::vector<std::vector<BufferBackground>> background_;
  std::vector<BackgroundFrame> background_frame_;  // per buffer, this frame's mask
  std::vector<CameraCache> cameras_;
  cv::Mat depth_;        // the current frame's depth map from the video camera (reused)
  int depth_rows_[2] = {0, -1};  // the rows of its window (DepthStage; -1: to the last)
  cv::Mat depth_range_;  // its 2x2 least and greatest depths, when the warp paints (reused)
  const Camera* frame_camera_ = nullptr;  // the current frame's camera and pose
  Rigid3d frame_cam_from_local_;
  int frames_seen_ = 0;
  // Exposure stage: the sums of the gains and offsets (B, G, R) over the frames it ran on
  // (identity where it could not tell), and how many.
  cv::Vec3d exposure_gain_sum_ = cv::Vec3d(0, 0, 0), exposure_offset_sum_ = cv::Vec3d(0, 0, 0);
  int exposure_frames_ = 0;
  // This frame's misalignment before correction, measured over every buffer's matches (the
  // pose fit's RMS over its inliers, pixels; without pose correction the RMS over every
  // buffer's inliers, texels); -1 when it could not tell.
  double frame_misalignment_px_ = -1;
  // The part of it a correction removes: sqrt(before^2 - after^2) of the same RMS with the
  // chosen correction (0 when the fit chose none: matching noise, movers); -1 as above. The
  // evidence refine.mode `auto` decides on.
  double frame_explained_px_ = -1;
};

// SelectActive (whether the exposure and select stages run): paint_stages.h.

// The background model's warm-up for these inputs: pipeline.background.warmup_frames, but with
// view selection on (SelectActive) at most a third of the frames the poses promise (at
// least 2): a capture of a few photos would otherwise never end its warm-up, every texel
// would stay provisional and the latest photo would win everywhere.
int EffectiveWarmupFrames(const PaintSessionInputs& inputs);

// The automatic texel size: the median depth the cameras see (rasterized at a few of the
// poses) / focal length, i.e. about one texel per pixel at the typical distance. Buffers
// larger than PipelineOptions::max_buffer_texels get coarser texels (base_buffer.h).
double AutomaticTexelSize(const Scene& scene, const Camera& camera,
                          const std::vector<Rigid3d>& cam_from_world);

}  // namespace fresco
