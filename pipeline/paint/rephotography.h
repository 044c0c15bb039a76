// Virtual rephotography (accuracy without ground truth): the painted model is rendered at a
// frame's pose and compared with the frame itself, where the model's surface is seen and
// painted. The held-out scorer (pipeline/rephoto/holdout_scorer.h) scores this way the frames
// `fresco bench`, `rephoto` and `eval` hold out of painting.
#pragma once

#include <opencv2/core.hpp>

#include "pipeline/core/rigid3.h"
#include "pipeline/core/scene.h"
#include "pipeline/render/renderer.h"

namespace fresco {

struct RephotoScore {
  double psnr_db = 0;
  double one_minus_ncc = 0;  // 0 = identical up to gain and offset, 1 = uncorrelated
  double completeness = 0;   // surface pixels that show painted texels
  int pixels = 0;            // pixels compared
};

// `frame_bgr`: the photo at `cam_from_world`, the renderer's camera size. A model with
// view-dependent layers is rendered with them (view_dependent_render.h).
RephotoScore ScoreRephoto(const Renderer& renderer, const Scene& painted,
                          const Rigid3d& cam_from_world, const cv::Mat& frame_bgr);

// What `fresco rephoto` keeps of a view besides the score.
struct RephotoView {
  cv::Mat rendered_bgr;  // CV_8UC3, the painted model at the pose; black where not painted
  cv::Mat compared;      // CV_8U, 255 at the pixels scored (painted surface seen)
  // LocalOneMinusNcc over `compared` (9 x 9 boxes): the protocol's 1 - NCC.
  double local_one_minus_ncc = 0;
  double image_coverage = 0;  // compared pixels / image pixels
};

// The same score, and the view (`view` must not be null).
RephotoScore ScoreRephoto(const Renderer& renderer, const Scene& painted,
                          const Rigid3d& cam_from_world, const cv::Mat& frame_bgr,
                          RephotoView* view);

}  // namespace fresco
