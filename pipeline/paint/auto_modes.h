// The `auto` value of refine.mode and background.mode: model only what the capture needs,
// decided from evidence measured on the capture itself (never from any ground truth), at a
// fixed decision point so the same input always gives the same result.
//
//   refinement  While deciding, each frame is registered to what the buffers hold but not
//               corrected (painting is what `off` paints). After `kRefineAutoFrames` frames
//               with a measurement, the median of the misalignment a correction would remove
//               (sqrt(before^2 - after^2) of the pose fit's RMS over its inliers, texels: the
//               part that is pose error, not matching noise or movers) is compared with
//               `kRefineAutoThresholdPx`: above, `robust`
//               refines every later frame; below, refinement stops (no further cost). It
//               stops too when none of the first frames could be registered at all.
//   background  The robust model runs from the start (masking as `robust` does). Once its
//               texels have warmed up, the foreground it finds among the texels it trusts is
//               counted frame by frame (its cleaned mask, before any growth by colour:
//               growth spreads whatever was flagged, and is no evidence of movers): once a fraction
//               above `kBackgroundAutoThreshold` (movers, or misaligned samples it keeps out) is
//               seen after `kBackgroundAutoFrames` frames, it stays; if none by a third of the
//               capture, the model is dropped and painting continues as `off`.
//               Captures from files decide before painting instead: every frame is compared
//               with the frames near it through the mesh (mover_masks.h), and the share of the
//               pixels that differ from most of them in compact regions (movers; not lines
//               along the image's edges: blur, misalignment, the mesh's error) is compared with
//               `kBackgroundAcrossViewsThreshold`: above, `robust` from the first frame; below,
//               `off` (no model, no warm-up).
#pragma once

#include <string>
#include <vector>

#include "pipeline/paint/stage_report.h"

namespace fresco {

// The misalignment a pose correction removes (texels): perfect poses 0-0.02 on the
// evaluation suites' first frames (with movers, exposure changes and distortion: the fit
// chooses no correction, however large the residual), pose noise 0.49-3.4 (docs/results.md,
// "Evaluation suite").
constexpr double kRefineAutoThresholdPx = 0.25;
constexpr int kRefineAutoFrames = 6;
// Refinement decides by this frame whatever it measured (off without a measurement: frames
// too small or too plain to register).
constexpr int kRefineAutoLastFrame = 20;
// ... and off by this frame when no frame so far gave a measurement (the frames cannot be
// registered to what is painted: on the suite's captures every frame from the second on
// measures; 10 photos of a castle 8-30 degrees apart measured 0 or 1).
constexpr int kRefineAutoNoEvidenceFrame = 4;
constexpr double kBackgroundAutoThreshold = 0.01;
// The share of the pixels found in compact regions across views (MoverMaskResult::compact)
// above which a capture has movers: synthetic captures without movers 0.00 %, with movers
// 0.70-6.03 % (evaluation suite; held out: 0.00 % against 0.80-4.45 %); real captures of
// static scenes 0.12-0.21 % (TUM's teddy, crop and whole room; docs/results.md).
constexpr double kBackgroundAcrossViewsThreshold = 0.004;
// The background decides on as soon as the fraction exceeds the threshold after this many
// frames, off when it has not after a third of the expected frames (at least this many, at
// most kBackgroundAutoMaxFrames): movers may enter late.
constexpr int kBackgroundAutoFrames = 8;
constexpr int kBackgroundAutoMaxFrames = 60;

// {"refine": D, "background": D, "update": D} as JSON text (the update's decision
// "mean" or "quality"), D = {"decision", "evidence", "threshold",
// "frames_measured", "decided_at_frame"} or null when that mode is not auto (metrics.json,
// eval.json).
std::string AutoDecisionsJson(const AutoDecisions& decisions);

// Collects the refinement evidence frame by frame and decides once.
class RefineAutoDecider {
 public:
  // `enabled`: the mode is auto (else the decision stays kNotAuto).
  void Start(bool enabled);
  // One frame's misalignment to the buffers, texels (< 0: could not tell; not counted).
  // `frame_number`: the session's frame count. Returns true when this frame decided.
  bool AddFrame(int frame_number, double misalignment_px);
  // Decides now (off) without evidence, e.g. when view selection excludes refinement.
  void DecideOff(int frame_number);
  // The joint pose adjustment's check, before painting (joint_pose_adjustment.h): frames left
  // out of the pose corrections agree `ratio` times better with the corrected frames, over
  // `frames` frames. Below `threshold` it vetoes `on`: where the misalignment measured says on,
  // the decision is off (basis "held_out_poses", evidence the ratio): a correction of the same
  // kind, per frame, would not make the frames agree better either. Kept through Start.
  void SetPoseCheck(double ratio, double threshold, int frames);
  const AutoDecision& decision() const { return decision_; }
  bool deciding() const { return decision_.state == AutoDecision::State::kDeciding; }

 private:
  AutoDecision decision_;
  std::vector<double> samples_;
  struct PoseCheck {
    double ratio = 0, threshold = 0;
    int frames = -1;  // < 0: none
  } pose_check_;
};

// Collects the background evidence frame by frame and decides once.
class BackgroundAutoDecider {
 public:
  // `warmup_frames`: the model's warm-up; evidence counts from then on. `expected_frames`:
  // the frames the capture promises (0: unknown).
  void Start(bool enabled, int warmup_frames, int expected_frames);
  // One frame's counts over the buffers seen: texels observed, still warming up, masked.
  // Returns true when this frame decided.
  bool AddFrame(int frame_number, long long observed, long long warming, long long masked);
  // Decides before the first frame from the movers found across views: `fraction` of the
  // pixels judged over `frames` frames masked.
  void DecideAcrossViews(double fraction, int frames);
  // Off, whatever was decided, because the frames held out agree better with the mean of
  // every view painted without the model (`gain_db` more PSNR; PaintSession::DecideUpdate).
  void OffByFramesHeldOut(int frame_number, double gain_db, int frames);
  const AutoDecision& decision() const { return decision_; }
  bool deciding() const { return decision_.state == AutoDecision::State::kDeciding; }

 private:
  AutoDecision decision_;
  int warmup_frames_ = 0, last_frames_ = kBackgroundAutoMaxFrames;
  long long trusted_ = 0, masked_ = 0;
};

}  // namespace fresco
