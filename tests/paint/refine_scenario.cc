#include "tests/paint/refine_scenario.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "pipeline/synth/procedural_scenes.h"
#include "tests/paint/rephotograph.h"
#include "tests/paint/room_capture.h"

namespace fresco::testing {

Status MakeRefineScenario(int frames, double pose_noise_deg, RefineScenario* scenario,
                          int seed) {
  CubeRoomOptions room;
  room.procedural_texture_px = 1024;
  FRESCO_RETURN_IF_ERROR(MakeCubeRoomScene(room, &scenario->scene));
  SynthOptions o = HandheldRoomCapture(frames, 0.6);
  o.turns = 0.5;
  o.pose_noise_deg = pose_noise_deg;
  o.seed = seed;
  return SynthesizeCapture(scenario->scene, o, &scenario->capture);
}

Status PaintScenario(const RefineScenario& scenario, const std::vector<PosedImage>& given,
                     const PipelineOptions& options, PaintedScenario* p,
                     const std::function<void(const FrameReport&)>& each_frame) {
  const SynthCapture& capture = scenario.capture;
  PaintSessionInputs inputs;
  inputs.scene = &scenario.scene;
  inputs.pipeline = options;
  inputs.typical_camera = &capture.camera;
  for (const auto& pose : capture.true_poses) inputs.expected_poses.push_back(pose.cam_from_world);
  FRESCO_RETURN_IF_ERROR(PaintSession::Create(inputs, &p->session));
  FrameReport report;
  int n = 0;
  for (size_t i = 0; i < capture.frames_bgr.size(); ++i) {
    Frame frame;
    frame.index = static_cast<int>(i);
    frame.bgr = capture.frames_bgr[i];
    p->session->PaintFrame(frame, capture.camera, given[i].cam_from_world, &report);
    p->total_ms += report.total_ms;
    if (each_frame) each_frame(report);
    if (const StageReport* r = report.Stage("refine")) {
      p->refine_ms += r->wall_ms;
      if (r->metrics.at("inliers") > 0) {
        p->refine_before_px += r->metrics.at("residual_before_px");
        p->refine_after_px += r->metrics.at("residual_after_px");
        p->refined += static_cast<int>(r->metrics.at("buffers_refined"));
        ++n;
      }
    }
  }
  if (n > 0) p->refine_before_px /= n, p->refine_after_px /= n;
  const double frames = std::max<size_t>(1, capture.frames_bgr.size());
  p->refine_ms /= frames;
  p->total_ms /= frames;
  p->scene = p->session->PaintedScene();
  return Status::Ok();
}

double ScenarioPsnr(const RefineScenario& scenario, const Scene& painted) {
  const SynthCapture& capture = scenario.capture;
  const Renderer renderer = RephotoRenderer(capture.camera);
  double sum = 0;
  int n = 0;
  for (size_t i = 0; i < capture.true_poses.size(); i += 6, ++n)
    sum += Rephotograph(renderer, scenario.scene, painted, capture.true_poses[i].cam_from_world)
               .psnr_db;
  return sum / n;
}

double MisalignmentPx(const PaintSession& session, const PaintSession& perfect) {
  RefineOptions o;
  o.mode = RefineMode::kRobust;
  o.search_px = 20;
  o.min_correction_px = 0;
  double sum_sq = 0;
  int n = 0;
  for (size_t b = 0; b < session.painted().size(); ++b) {
    const cv::Mat& bgra = session.painted()[b].bgra;
    cv::Mat bgr, alpha;
    cv::cvtColor(bgra, bgr, cv::COLOR_BGRA2BGR);
    cv::extractChannel(bgra, alpha, 3);
    const RefineEstimate e = EstimateRefinement(bgr, alpha == 255, perfect.painted()[b].bgra, o);
    sum_sq += e.inliers * e.residual_before_px * e.residual_before_px;
    n += e.inliers;
  }
  return n > 0 ? std::sqrt(sum_sq / n) : 0;
}

}  // namespace fresco::testing
