#include "pipeline/eval/eval_run.h"

#include <chrono>
#include <map>
#include <memory>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/capture.h"
#include "pipeline/core/project.h"
#include "pipeline/eval/eval_score.h"
#include "pipeline/eval/mover_provenance.h"
#include "pipeline/paint/joint_pose_adjustment.h"
#include "pipeline/paint/mover_masks.h"
#include "pipeline/paint/open_project.h"
#include "pipeline/paint/rephotography.h"
#include "pipeline/render/renderer.h"
#include "pipeline/synth/synth_writer.h"

namespace fresco {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The held-out frames of a painting run, with their truth.
struct HeldOut {
  Frame frame;
  Rigid3d given_cam_from_world;
  int plan_index = 0;  // into the synth plan (true pose, gain)
};

}  // namespace

// The references for EvalOptions::recovery: the capture painted again with refinement off
// (no pose correction at all: neither frame by frame nor joint), and at the true poses.
static Status PaintReferences(const EvalSuite& suite, const SuiteCapture& capture,
                              const EvalOptions& options, CaptureEval* result) {
  EvalOptions reference = options;
  reference.recovery = false;
  reference.progress = nullptr;
  reference.overrides.push_back("pipeline.refine.mode=off");
  reference.overrides.push_back("pipeline.refine.joint=false");
  CaptureEval unrefined;
  FRESCO_RETURN_IF_ERROR(EvaluateCapture(suite, capture, reference, &unrefined));
  result->unrefined_truth_psnr_db = unrefined.truth_psnr_db;
  if (!result->noisy_poses) return Status::Ok();
  reference.overrides = options.overrides;
  reference.true_poses = true;
  CaptureEval perfect;
  FRESCO_RETURN_IF_ERROR(EvaluateCapture(suite, capture, reference, &perfect));
  result->true_pose_truth_psnr_db = perfect.truth_psnr_db;
  const double lost = perfect.truth_psnr_db - unrefined.truth_psnr_db;
  if (lost >= 0.5) result->recovered = (result->truth_psnr_db - unrefined.truth_psnr_db) / lost;
  return Status::Ok();
}

Status EvalOptions::Check() const {
  if (cache_dir.empty()) return Status::Error("cache: no folder for the captures");
  if (holdout < 2) return Status::Error("holdout: must be >= 2");
  if (!(leak_threshold > 0 && leak_threshold < 255))
    return Status::Error("leak_threshold: must be in (0, 255)");
  return Status::Ok();
}

Status EvaluateCapture(const EvalSuite& suite, const SuiteCapture& capture,
                       const EvalOptions& options, CaptureEval* result) {
  FRESCO_RETURN_IF_ERROR(options.Check());
  *result = CaptureEval();
  result->name = capture.name;
  result->family = capture.family;
  SynthJob job;
  FRESCO_RETURN_IF_ERROR(BuildSuiteCaptureJob(suite, capture, &job));
  const std::string dir = options.cache_dir + "/" + capture.name;
  SynthWriteOptions write_options;
  write_options.skip_if_current = true;
  write_options.scene_source = job.scene_source;
  write_options.stop = options.stop;
  SynthWriteResult written;
  const auto generate_start = Clock::now();
  FRESCO_RETURN_IF_ERROR(WriteSynthCapture(job.scene, job.options, dir, write_options, &written));
  result->generated = !written.skipped;
  result->generate_seconds = SecondsSince(generate_start);
  SynthCapture plan;  // true poses, gains, movers (no pixels)
  FRESCO_RETURN_IF_ERROR(PlanSynthCapture(job.scene, job.options, &plan));
  std::map<std::string, int> plan_index;
  for (size_t k = 0; k < plan.true_poses.size(); ++k) plan_index[plan.true_poses[k].name] = k;

  Project project;
  FRESCO_RETURN_IF_ERROR(LoadProject(dir + "/project.json", options.overrides, &project));
  cv::setNumThreads(project.pipeline.threads > 0 ? project.pipeline.threads : -1);
  Capture loaded;
  std::unique_ptr<PaintSession> session;
  FRESCO_RETURN_IF_ERROR(OpenPaintSession(project, &loaded, &session));

  // Where movers pass, which painted texels took their colour from one.
  std::unique_ptr<MoverProvenance> provenance;
  std::vector<HeldOut> held_out;
  std::vector<PaintedFrameCentre> painted_frames;
  double paint_seconds = 0;
  Frame frame;
  Status read_status;
  FrameReport report;
  // The frames to paint, read first (the joint adjustment needs them all).
  struct PaintFrame {
    Frame frame;
    Rigid3d painted_pose;
    const Camera* camera = nullptr;
    int plan_k = 0;
    Rigid3d true_pose;
  };
  std::vector<PaintFrame> to_paint;
  while (loaded.video->Next(&frame, &read_status)) {
    if (options.stop && options.stop()) return Status::Error(dir + ": interrupted");
    const int index = result->frames++;
    const PosedImage* pose = loaded.PoseForFrame(frame);
    if (!pose || !loaded.CameraFor(*pose)) continue;
    const auto k = plan_index.find(pose->name);
    if (k == plan_index.end())
      return Status::Error(dir + ": frame " + pose->name + " is not in the synth plan");
    if (index % options.holdout == options.holdout / 2) {
      held_out.push_back({frame, pose->cam_from_world, k->second});
      continue;
    }
    const Rigid3d& true_pose = plan.true_poses[k->second].cam_from_world;
    // Beyond what writing the poses as text rounds off (a micrometre, a microradian).
    if ((true_pose.Centre() - pose->cam_from_world.Centre()).norm() > 1e-6 ||
        true_pose.rotation.angularDistance(pose->cam_from_world.rotation) > 1e-6)
      result->noisy_poses = true;
    const Rigid3d& painted_pose = options.true_poses ? true_pose : pose->cam_from_world;
    const Camera& camera = *loaded.CameraFor(*pose);
    to_paint.push_back({frame, painted_pose, &camera, k->second, true_pose});
    to_paint.back().frame.bgr = frame.bgr.clone();  // the source may reuse its buffer
  }
  FRESCO_RETURN_IF_ERROR(read_status);
  if (project.pipeline.refine.joint) {  // all poses adjusted together before painting
    std::vector<PoseAdjustFrame> adjust;
    for (const PaintFrame& pf : to_paint)
      adjust.push_back({pf.frame.bgr, pf.camera, CamFromLocal(loaded.scene, pf.painted_pose)});
    PoseAdjustResult adjusted;
    FRESCO_RETURN_IF_ERROR(
        AdjustPosesOnMesh(loaded.scene.mesh, adjust, PoseAdjustOptions(), &adjusted));
    const Rigid3d local_from_world(Eigen::Quaterniond::Identity(), -loaded.scene.origin_in_world);
    for (size_t k = 0; k < to_paint.size(); ++k)
      to_paint[k].painted_pose = adjusted.cam_from_local[k] * local_from_world;
  }
  if (NeedsMoversAcrossViews(project.pipeline.background)) {  // movers found first
    const MoverMaskOptions mover_options = MoverMaskOptionsFor(project.pipeline.background);
    std::vector<MoverMaskFrame> frames;
    for (const PaintFrame& pf : to_paint) {
      MoverMaskFrame f;
      cv::resize(pf.frame.bgr, f.bgr, MoverMaskSize(*pf.camera, mover_options), 0, 0,
                 cv::INTER_AREA);
      f.camera = pf.camera;
      f.cam_from_local = CamFromLocal(loaded.scene, pf.painted_pose);
      frames.push_back(f);
    }
    MoverMaskResult found;
    FRESCO_RETURN_IF_ERROR(FindMoverMasks(loaded.scene.mesh, frames, mover_options, &found));
    session->DecideBackgroundAcrossViews(found.fraction(), static_cast<int>(frames.size()));
    if (project.pipeline.background.across_views &&
        session->options().background.mode != BackgroundMode::kOff)
      for (size_t k = 0; k < to_paint.size(); ++k) to_paint[k].frame.movers = found.Packed(k);
    result->movers_across_views = found.fraction();
  }
  for (const PaintFrame& pf : to_paint) {
    const Frame& frame = pf.frame;
    const Rigid3d& painted_pose = pf.painted_pose;
    const Camera& camera = *pf.camera;
    const Rigid3d& true_pose = pf.true_pose;
    const int plan_k = pf.plan_k;
    if (!plan.movers.empty() && !provenance)
      provenance =
          std::make_unique<MoverProvenance>(job.scene, plan.movers, loaded.scene, camera, *session);
    if (provenance) provenance->BeforeFrame(*session);
    const auto start = Clock::now();
    session->PaintFrame(frame, camera, painted_pose, &report);
    paint_seconds += SecondsSince(start);
    if (!report.painted) continue;
    if (provenance) provenance->AfterFrame(*session, plan_k, true_pose, painted_pose);
    ++result->painted_frames;
    painted_frames.push_back({plan_k, plan.true_poses[plan_k].cam_from_world.Centre()});
  }
  result->paint_fps = paint_seconds > 0 ? result->painted_frames / paint_seconds : 0.0;
  result->coverage = session->Coverage();
  result->decisions = session->auto_decisions();
  result->has_movers = !plan.movers.empty();
  result->holdout_frames = static_cast<int>(held_out.size());

  const Scene painted = session->PaintedScene();
  Scene mover_texels;
  if (provenance) {
    mover_texels = session->PaintedScene(provenance->MaskImages(*session));
    const MoverProvenance::Figures f = provenance->Count(*session);
    result->mover_texels = f.mover_fraction();
    const auto share = [&](long long texels) {
      return f.painted > 0 ? static_cast<double>(texels) / f.painted : 0.0;
    };
    result->mover_dominated_texels = share(f.mover_dominated);
    result->open_coverage = f.open_coverage();
    result->mover_never_open = share(f.mover_never_open);
    result->mover_open_masked = share(f.mover_open_masked);
    result->mover_open_passed = share(f.mover_open_passed);
    result->mover_open_replaced = share(f.mover_open_replaced);
  }
  const Renderer painted_renderer(plan.camera, RenderOptions());
  RenderOptions clean_options;
  clean_options.raster.supersample = job.options.supersample;
  const Renderer clean_renderer(plan.camera, clean_options);
  long long painted_pixels = 0, leak_pixels = 0, region_error_pixels = 0;
  int scored = 0, truth_scored = 0;
  for (const HeldOut& h : held_out) {
    if (options.stop && options.stop()) return Status::Error(dir + ": interrupted");
    const RephotoScore s =
        ScoreRephoto(painted_renderer, painted, h.given_cam_from_world, h.frame.bgr);
    result->completeness += s.completeness / held_out.size();
    if (s.pixels > 0) {
      result->psnr_db += s.psnr_db, result->one_minus_ncc += s.one_minus_ncc;
      ++scored;
    }
    TruthViewInputs in;
    in.painted_renderer = &painted_renderer;
    in.clean_renderer = &clean_renderer;
    in.painted = &painted;
    in.truth = &job.scene;
    in.true_cam_from_world = plan.true_poses[h.plan_index].cam_from_world;
    in.exposure_gain = plan.exposure_gains[h.plan_index];
    in.movers = &plan.movers;
    in.painted_frames = &painted_frames;
    in.leak_threshold = options.leak_threshold;
    in.mover_texels = provenance ? &mover_texels : nullptr;
    const TruthViewScore t = ScoreTruthView(in);
    if (t.painted_pixels > 0) {
      result->truth_psnr_db += t.psnr_db, result->truth_one_minus_ncc += t.one_minus_ncc;
      ++truth_scored;
    }
    painted_pixels += t.painted_pixels;
    leak_pixels += t.leak_pixels;
    region_error_pixels += t.region_error_pixels;
  }
  if (scored > 0) result->psnr_db /= scored, result->one_minus_ncc /= scored;
  if (truth_scored > 0)
    result->truth_psnr_db /= truth_scored, result->truth_one_minus_ncc /= truth_scored;
  result->mover_leak = painted_pixels > 0 ? double(leak_pixels) / painted_pixels : 0.0;
  result->mover_region_error =
      painted_pixels > 0 ? double(region_error_pixels) / painted_pixels : 0.0;
  if (options.recovery) FRESCO_RETURN_IF_ERROR(PaintReferences(suite, capture, options, result));
  return Status::Ok();
}

Status EvaluateSuite(const EvalSuite& suite, const EvalOptions& options,
                     std::vector<CaptureEval>* results) {
  results->clear();
  const int total = static_cast<int>(suite.captures.size());
  for (int i = 0; i < total; ++i) {
    const SuiteCapture& c = suite.captures[i];
    if (options.progress) options.progress(i, total, c.name + " started");
    CaptureEval r;
    FRESCO_RETURN_IF_ERROR(EvaluateCapture(suite, c, options, &r));
    results->push_back(r);
    if (options.progress) {
      char line[200];
      std::snprintf(line, sizeof line, "%s: truth %.2f dB, rephoto %.2f dB, leak %.3f %%, %.0f fps",
                    c.name.c_str(), r.truth_psnr_db, r.psnr_db, 100 * r.mover_leak, r.paint_fps);
      options.progress(i + 1, total, line);
    }
  }
  return Status::Ok();
}

}  // namespace fresco
