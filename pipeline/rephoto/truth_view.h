// The truth view of a held-out frame of a synthetic capture, where the truth is known: the
// painted model rendered at the frame's TRUE pose against the static scene rendered there
// with the frame's exposure gain (no movers): how close the painted texture is to the true
// one where it is seen. HoldoutScorer (holdout_scorer.h) scores every held-out frame of a
// capture with a SceneTruth this way, beside the rephotography at the given pose.
//
//   truth          PSNR and 1 - NCC over the pixels where both show the surface and the
//                  model is painted;
//   mover leak     of those painted pixels, the ones whose colour came from a mover (the
//                  texels MoverProvenance followed, rendered as a texture);
//   mover region error  of the painted pixels, those off the clean render by more than
//                  `leak_threshold` levels (any channel) at a surface point that a mover hid
//                  from the camera in at least one painted frame (movers, and any other error
//                  there: misalignment, exposure).
#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "pipeline/core/rigid3.h"
#include "pipeline/core/scene.h"
#include "pipeline/render/renderer.h"
#include "pipeline/synth/movers.h"

namespace fresco {

// Where the camera was (true centre, world) at each painted frame, to tell which surface
// points a mover hid at some time.
struct PaintedFrameCentre {
  int frame = 0;
  Eigen::Vector3d centre_world = Eigen::Vector3d::Zero();
};

// What a synthetic capture knows besides its frames, for all of its held-out frames.
struct SceneTruth {
  const Scene* scene = nullptr;        // the static scene the frames were made of (world)
  const Renderer* renderer = nullptr;  // the capture's camera, the capture's supersampling
  // Where the movers were (optional: without them no mover figures).
  const std::vector<MoverOptions>* movers = nullptr;
  const std::vector<PaintedFrameCentre>* painted_frames = nullptr;
  double leak_threshold = 40.0;  // levels (0..255), largest channel difference
  // The painted scene with MoverProvenance::MaskImages as its texture, or null.
  const Scene* mover_texels = nullptr;
};

struct TruthViewInputs {
  const Renderer* painted_renderer = nullptr;  // the capture's camera, 1 sample per pixel
  const Scene* painted = nullptr;              // PaintSession::PaintedScene()
  const SceneTruth* truth = nullptr;
  Rigid3d true_cam_from_world;
  double exposure_gain = 1.0;  // the frame's
};

struct TruthViewScore {
  double psnr_db = 0;        // painted vs clean, where both show the surface and it is painted
  double one_minus_ncc = 0;  // the same pixels, gain- and offset-invariant
  long long painted_pixels = 0;
  long long leak_pixels = 0;          // painted pixels showing a mover (with mover_texels)
  long long region_error_pixels = 0;  // painted pixels off where a mover passed
};

TruthViewScore ScoreTruthView(const TruthViewInputs& inputs);

// Does the segment from `from` to `to` pass within `radius` of `centre`?
bool SegmentNearPoint(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                      const Eigen::Vector3d& centre, double radius);

}  // namespace fresco
