// The one scorer of held-out frames: frames held out of painting are given to it one at a
// time after the run, each with its pose (and, where known, its true pose, and a synthetic
// capture's truth); it renders the painted model there (with its view-dependent layers:
// view_dependent_render.h) and adds up the figures. `fresco bench` (every N-th frame),
// `fresco rephoto` (one frame left out per run) and `fresco eval` (every N-th frame of a
// synthetic capture) score with it, so the three measure alike:
//
//   rephotography  the model at the frame's GIVEN pose against the frame itself
//                  (rephotography.h): PSNR and 1 - NCC over the pixels where painted
//                  surface is seen, completeness (surface pixels painted); needs no truth;
//   truth          at the frame's TRUE pose: against the static scene rendered there with
//                  the frame's exposure when the capture's SceneTruth is known (truth_view.h,
//                  with the mover figures), else against the frame itself.
//
//   HoldoutScorer scorer(session->PaintedScene(), HoldoutScorerOptions());  // after painting
//   for (const HeldOutFrame& frame : held_out) scorer.Add(frame);
//   const HoldoutFigures& f = scorer.figures();   // means; NaN where nothing was compared
#pragma once

#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/core/camera.h"
#include "pipeline/core/capture.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/scene.h"
#include "pipeline/paint/rephotography.h"
#include "pipeline/render/renderer.h"
#include "pipeline/rephoto/truth_view.h"
#include "pipeline/run/paint_run.h"

namespace fresco {

// One frame held out of painting.
struct HeldOutFrame {
  cv::Mat photo_bgr;               // CV_8UC3, the camera's size
  const Camera* camera = nullptr;  // the camera the model is rendered through
  Rigid3d cam_from_world;          // the pose the frame was given
  // The frame's true pose where known (a synthetic capture's); without it no truth figures.
  std::optional<Rigid3d> true_cam_from_world;
  double exposure_gain = 1.0;  // with a SceneTruth: the frame's exposure against the scene's
};

// A frame the run held out (fate kHeldOut): its photo, camera and pose; with `truth_from`,
// its true pose from that capture's truth poses (Capture::truth_poses) when it has one.
HeldOutFrame HeldOutFrameOf(const RunFrame& frame, const Capture* truth_from = nullptr);

struct HoldoutScorerOptions {
  // A synthetic capture's truth: the truth figures compare with the static scene at the true
  // pose (truth_view.h); null: with the frame itself there. Must outlive the scorer.
  const SceneTruth* truth = nullptr;
  // Keep each frame's RephotoView (the render, the compared pixels, the local 9 x 9 1 - NCC
  // of `fresco rephoto`); the local 1 - NCC is then averaged too.
  bool keep_views = false;
};

// One frame's scores.
struct HeldOutScore {
  RephotoScore rephoto;  // at the given pose, against the frame
  RephotoView view;      // with HoldoutScorerOptions::keep_views
  // At the true pose (when the frame has one): against the frame, or with a SceneTruth
  // against the scene (and only then with mover figures).
  std::optional<TruthViewScore> truth;
};

inline constexpr double kNotScored = std::numeric_limits<double>::quiet_NaN();

// The figures over the frames scored so far. Means are NaN where no frame had a pixel to
// compare; each client says what it reports then.
struct HoldoutFigures {
  int frames = 0;                           // held-out frames given
  int scored = 0;                           // ... with painted surface seen at their given poses
  double psnr_db = kNotScored;              // mean over `scored`
  double one_minus_ncc = kNotScored;        // mean over `scored` (over all compared pixels)
  double local_one_minus_ncc = kNotScored;  // keep_views: mean over `scored` (9 x 9 boxes)
  double completeness = kNotScored;         // mean over `frames`
  int truth_frames = 0;                     // frames with a true pose
  int truth_scored = 0;                     // ... with painted surface seen there
  double truth_psnr_db = kNotScored;        // mean over `truth_scored`
  double truth_one_minus_ncc = kNotScored;  // mean over `truth_scored`
  // With a SceneTruth with movers, summed over the truth views: painted pixels, those showing
  // a mover, those off where a mover passed (TruthViewScore).
  long long truth_painted_pixels = 0, leak_pixels = 0, region_error_pixels = 0;

  double MoverLeak() const {
    return truth_painted_pixels > 0 ? double(leak_pixels) / truth_painted_pixels : 0.0;
  }
  double MoverRegionError() const {
    return truth_painted_pixels > 0 ? double(region_error_pixels) / truth_painted_pixels : 0.0;
  }
};

class HoldoutScorer {
 public:
  // `painted`: the painted model (PaintSession::PaintedScene()).
  HoldoutScorer(Scene painted, const HoldoutScorerOptions& options);

  // Renders the model at the frame's pose (and true pose), scores and adds to the figures.
  // The result stays valid until the next Add.
  const HeldOutScore& Add(const HeldOutFrame& frame);
  // Add for each frame in order, asking `stop` (optional) before each: false when it said
  // stop (a Ctrl-C between frames).
  bool AddAll(const std::vector<HeldOutFrame>& frames, const std::function<bool()>& stop);

  const HoldoutFigures& figures() const { return figures_; }
  const Scene& painted() const { return painted_; }

 private:
  const Renderer& RendererFor(const Camera& camera);

  Scene painted_;
  HoldoutScorerOptions options_;
  std::map<const Camera*, std::unique_ptr<Renderer>> renderers_;  // ray tables built once
  HeldOutScore last_;
  HoldoutFigures figures_;
  // Sums behind the means.
  double psnr_sum_ = 0, ncc_sum_ = 0, local_ncc_sum_ = 0, completeness_sum_ = 0;
  double truth_psnr_sum_ = 0, truth_ncc_sum_ = 0;
};

}  // namespace fresco
