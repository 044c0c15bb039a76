#include "pipeline/eval/eval_run.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>

#include <opencv2/core/utility.hpp>

#include "pipeline/core/capture.h"
#include "pipeline/core/project.h"
#include "pipeline/eval/mover_provenance.h"
#include "pipeline/render/renderer.h"
#include "pipeline/rephoto/holdout_scorer.h"
#include "pipeline/run/paint_job.h"
#include "pipeline/run/paint_run.h"
#include "pipeline/synth/synth_writer.h"

namespace fresco {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// A capture as generated, with its truth: the generator's plan (true and given poses,
// exposure gains, movers) and each frame's index in it by name.
struct GeneratedCapture {
  std::string dir;  // CACHE/NAME
  SynthJob job;
  SynthCapture plan;  // no pixels
  std::map<std::string, int> plan_index;

  // Frame `name`'s index into the plan.
  Status PlanIndex(const std::string& name, int* k) const {
    const auto found = plan_index.find(name);
    if (found == plan_index.end())
      return Status::Error(dir + ": frame " + name + " is not in the synth plan");
    *k = found->second;
    return Status::Ok();
  }
};

// Writes the capture into the cache (or finds it current there) and plans its truth.
Status GenerateCapture(const EvalSuite& suite, const SuiteCapture& capture,
                       const EvalOptions& options, GeneratedCapture* generated,
                       CaptureEval* result) {
  FRESCO_RETURN_IF_ERROR(BuildSuiteCaptureJob(suite, capture, &generated->job));
  const SynthJob& job = generated->job;
  generated->dir = options.cache_dir + "/" + capture.name;
  SynthWriteOptions write_options;
  write_options.skip_if_current = true;
  write_options.scene_source = job.scene_source;
  write_options.stop = options.stop;
  SynthWriteResult written;
  const auto generate_start = Clock::now();
  FRESCO_RETURN_IF_ERROR(
      WriteSynthCapture(job.scene, job.options, generated->dir, write_options, &written));
  result->generated = !written.skipped;
  result->generate_seconds = SecondsSince(generate_start);
  FRESCO_RETURN_IF_ERROR(PlanSynthCapture(job.scene, job.options, &generated->plan));
  const std::vector<PosedImage>& true_poses = generated->plan.true_poses;
  for (size_t k = 0; k < true_poses.size(); ++k) generated->plan_index[true_poses[k].name] = k;
  return Status::Ok();
}

// Do two poses differ beyond what writing them as text rounds off (a micrometre, a
// microradian)?
bool PosesDiffer(const Rigid3d& a, const Rigid3d& b) {
  return (a.Centre() - b.Centre()).norm() > 1e-6 || a.rotation.angularDistance(b.rotation) > 1e-6;
}

// What painting a capture leaves for scoring.
struct PaintedCapture {
  std::vector<HeldOutFrame> held_out;  // with their true poses and exposure gains
  std::vector<PaintedFrameCentre> painted_frames;
  // Where movers pass, which painted texels took their colour from one.
  std::unique_ptr<MoverProvenance> provenance;
};

// Paints the opened capture through the painting job's run, every `holdout`-th frame held
// out; follows the movers' provenance around each painted frame.
Status PaintCapture(const Project& project, const GeneratedCapture& g, const EvalOptions& options,
                    PaintJob* job, PaintedCapture* painted, CaptureEval* result) {
  PaintSession& session = *job->session;
  PaintRunOptions run_options;
  run_options.max_frames = project.pipeline.max_frames;
  run_options.holdout_every = options.holdout;
  PaintRun run(&session, job->source.get(), run_options);
  double paint_seconds = 0;
  Clock::time_point paint_start;
  int plan_k = 0;
  PaintRunHooks hooks;
  hooks.stop = options.stop;
  hooks.before_paint = [&](const RunFrame& f) {
    FRESCO_RETURN_IF_ERROR(g.PlanIndex(f.pose_name, &plan_k));
    if (PosesDiffer(g.plan.true_poses[plan_k].cam_from_world,
                    g.plan.given_poses[plan_k].cam_from_world))
      result->noisy_poses = true;
    if (!g.plan.movers.empty() && !painted->provenance)
      painted->provenance = std::make_unique<MoverProvenance>(g.job.scene, g.plan.movers,
                                                              job->scene(), *f.camera, session);
    if (painted->provenance) painted->provenance->BeforeFrame(session);
    paint_start = Clock::now();
    return Status::Ok();
  };
  hooks.after_frame = [&](const RunFrame& f, const FrameReport* report) {
    if (f.fate == FrameFate::kPaint) paint_seconds += SecondsSince(paint_start);
    if (f.fate == FrameFate::kHeldOut) {
      int k = 0;
      FRESCO_RETURN_IF_ERROR(g.PlanIndex(f.pose_name, &k));
      HeldOutFrame h = HeldOutFrameOf(f);
      h.camera = &g.plan.camera;  // as the truth's renderer
      h.true_cam_from_world = g.plan.true_poses[k].cam_from_world;
      h.exposure_gain = g.plan.exposure_gains[k];
      painted->held_out.push_back(h);
    }
    if (!report) return Status::Ok();  // not painted
    const Rigid3d& true_pose = g.plan.true_poses[plan_k].cam_from_world;
    if (painted->provenance)
      painted->provenance->AfterFrame(session, plan_k, true_pose, f.posed.cam_from_world);
    painted->painted_frames.push_back({plan_k, true_pose.Centre()});
    return Status::Ok();
  };
  FRESCO_RETURN_IF_ERROR(RunToEnd(&run, hooks));
  if (options.stop && options.stop()) return Status::Error(g.dir + ": interrupted");
  const PaintRunStats& stats = run.stats();
  result->frames = stats.frames;
  result->painted_frames = stats.frames_painted;
  result->holdout_frames = stats.frames_held_out;
  result->paint_fps = paint_seconds > 0 ? result->painted_frames / paint_seconds : 0.0;
  result->coverage = session.Coverage();
  result->decisions = session.auto_decisions();
  if (job->mover_masks) result->movers_across_views = job->mover_masks->compact_fraction();
  if (const auto& joint = job->joint_poses; joint && joint->not_run.empty()) {
    const auto ratio = [](double before, double after) { return after > 0 ? before / after : 0; };
    result->joint_ran = true;
    result->joint_applied = joint->applied;
    result->joint_decided_on_frames = joint->decided_on_frames;
    result->joint_check_ratio = ratio(joint->check_before_px, joint->check_after_px);
    result->joint_tracks_ratio = ratio(joint->rms_before_px, joint->rms_after_px);
    result->joint_one_end_ratio = ratio(joint->check_before_px, joint->check_one_end_px);
  }
  return Status::Ok();
}

// The texel-space mover figures (MoverProvenance::Figures) as shares.
void CountMoverTexels(const MoverProvenance& provenance, const PaintSession& session,
                      CaptureEval* result) {
  const MoverProvenance::Figures f = provenance.Count(session);
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

// Scores the held-out frames with the one scorer: rephotography at the given poses, the
// truth (the static scene) at the true poses, the mover figures.
Status ScoreCapture(const GeneratedCapture& g, const EvalOptions& options,
                    const PaintSession& session, const PaintedCapture& painted,
                    CaptureEval* result) {
  Scene mover_texels;
  if (painted.provenance) {
    mover_texels = session.PaintedScene(painted.provenance->MaskImages(session));
    CountMoverTexels(*painted.provenance, session, result);
  }
  RenderOptions clean_options;
  clean_options.raster.supersample = g.job.options.supersample;
  const Renderer clean_renderer(g.plan.camera, clean_options);
  SceneTruth truth;
  truth.scene = &g.job.scene;
  truth.renderer = &clean_renderer;
  truth.movers = &g.plan.movers;
  truth.painted_frames = &painted.painted_frames;
  truth.leak_threshold = options.leak_threshold;
  truth.mover_texels = painted.provenance ? &mover_texels : nullptr;
  HoldoutScorerOptions scorer_options;
  scorer_options.truth = &truth;
  HoldoutScorer scorer(session.PaintedScene(), scorer_options);
  if (!scorer.AddAll(painted.held_out, options.stop)) return Status::Error(g.dir + ": interrupted");
  // A figure no frame could give is reported as 0.
  const auto or_zero = [](double v) { return std::isnan(v) ? 0.0 : v; };
  const HoldoutFigures& f = scorer.figures();
  result->psnr_db = or_zero(f.psnr_db);
  result->one_minus_ncc = or_zero(f.one_minus_ncc);
  result->completeness = or_zero(f.completeness);
  result->truth_psnr_db = or_zero(f.truth_psnr_db);
  result->truth_one_minus_ncc = or_zero(f.truth_one_minus_ncc);
  result->mover_leak = f.MoverLeak();
  result->mover_region_error = f.MoverRegionError();
  return Status::Ok();
}

// The references for EvalOptions::recovery: the capture painted again with refinement off
// (no pose correction at all: neither frame by frame nor joint), and at the true poses.
Status PaintReferences(const EvalSuite& suite, const SuiteCapture& capture,
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

}  // namespace

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
  GeneratedCapture generated;
  FRESCO_RETURN_IF_ERROR(GenerateCapture(suite, capture, options, &generated, result));
  result->has_movers = !generated.plan.movers.empty();

  Project project;
  FRESCO_RETURN_IF_ERROR(LoadProject(generated.dir + "/project.json", options.overrides, &project));
  cv::setNumThreads(project.pipeline.threads > 0 ? project.pipeline.threads : -1);
  // The held-out frames take no part in what is done with the whole capture before painting
  // (the joint adjustment of the poses, the movers found across views).
  PaintJobOptions job_options;
  job_options.joint_holdout_every = options.holdout;
  job_options.stop = options.stop;
  job_options.paint_at_truth_poses = options.true_poses;
  std::unique_ptr<PaintJob> job;
  FRESCO_RETURN_IF_ERROR(OpenPaintJob(project, job_options, &job));
  PaintedCapture painted;
  FRESCO_RETURN_IF_ERROR(PaintCapture(project, generated, options, job.get(), &painted, result));
  FRESCO_RETURN_IF_ERROR(ScoreCapture(generated, options, *job->session, painted, result));
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
