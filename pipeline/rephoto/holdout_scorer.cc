#include "pipeline/rephoto/holdout_scorer.h"

#include <utility>

namespace fresco {

HeldOutFrame HeldOutFrameOf(const RunFrame& frame, const Capture* truth_from) {
  HeldOutFrame held_out;
  held_out.photo_bgr = frame.posed.frame.bgr;
  held_out.camera = frame.camera;
  held_out.cam_from_world = frame.posed.cam_from_world;
  const size_t k = frame.pose_index;
  if (truth_from && frame.pose_index >= 0 && k < truth_from->truth_poses.size())
    held_out.true_cam_from_world = truth_from->truth_poses[k].cam_from_world;
  return held_out;
}

HoldoutScorer::HoldoutScorer(Scene painted, const HoldoutScorerOptions& options)
    : painted_(std::move(painted)), options_(options) {}

const Renderer& HoldoutScorer::RendererFor(const Camera& camera) {
  std::unique_ptr<Renderer>& renderer = renderers_[&camera];
  if (!renderer) renderer = std::make_unique<Renderer>(camera, RenderOptions());
  return *renderer;
}

const HeldOutScore& HoldoutScorer::Add(const HeldOutFrame& frame) {
  const Renderer& renderer = RendererFor(*frame.camera);
  HeldOutScore& score = last_;
  score = HeldOutScore();
  score.rephoto =
      options_.keep_views
          ? ScoreRephoto(renderer, painted_, frame.cam_from_world, frame.photo_bgr, &score.view)
          : ScoreRephoto(renderer, painted_, frame.cam_from_world, frame.photo_bgr);
  HoldoutFigures& f = figures_;
  ++f.frames;
  completeness_sum_ += score.rephoto.completeness;
  f.completeness = completeness_sum_ / f.frames;
  if (score.rephoto.pixels > 0) {
    ++f.scored;
    psnr_sum_ += score.rephoto.psnr_db;
    ncc_sum_ += score.rephoto.one_minus_ncc;
    f.psnr_db = psnr_sum_ / f.scored;
    f.one_minus_ncc = ncc_sum_ / f.scored;
    if (options_.keep_views) {
      local_ncc_sum_ += score.view.local_one_minus_ncc;
      f.local_one_minus_ncc = local_ncc_sum_ / f.scored;
    }
  }
  if (!frame.true_cam_from_world) return score;

  ++f.truth_frames;
  const Rigid3d& true_pose = *frame.true_cam_from_world;
  TruthViewScore& t = score.truth.emplace();
  if (options_.truth) {  // the static scene at the true pose
    TruthViewInputs in;
    in.painted_renderer = &renderer;
    in.painted = &painted_;
    in.truth = options_.truth;
    in.true_cam_from_world = true_pose;
    in.exposure_gain = frame.exposure_gain;
    t = ScoreTruthView(in);
  } else {  // the frame itself at the true pose (rendered again only where it differs)
    const bool same = true_pose.rotation.coeffs() == frame.cam_from_world.rotation.coeffs() &&
                      true_pose.translation == frame.cam_from_world.translation;
    const RephotoScore r =
        same ? score.rephoto : ScoreRephoto(renderer, painted_, true_pose, frame.photo_bgr);
    t.psnr_db = r.psnr_db, t.one_minus_ncc = r.one_minus_ncc, t.painted_pixels = r.pixels;
  }
  f.truth_painted_pixels += t.painted_pixels;
  f.leak_pixels += t.leak_pixels;
  f.region_error_pixels += t.region_error_pixels;
  if (t.painted_pixels > 0) {
    ++f.truth_scored;
    truth_psnr_sum_ += t.psnr_db;
    truth_ncc_sum_ += t.one_minus_ncc;
    f.truth_psnr_db = truth_psnr_sum_ / f.truth_scored;
    f.truth_one_minus_ncc = truth_ncc_sum_ / f.truth_scored;
  }
  return score;
}

bool HoldoutScorer::AddAll(const std::vector<HeldOutFrame>& frames,
                           const std::function<bool()>& stop) {
  for (const HeldOutFrame& frame : frames) {
    if (stop && stop()) return false;
    Add(frame);
  }
  return true;
}

}  // namespace fresco
