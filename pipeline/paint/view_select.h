// Select stage (pipeline.select; runs after background, before paint): which texels take this
// frame's sample. Per texel a view score, pixels per texel times the cosine of the view angle
// (the warp's quality without its cap at one pixel per texel, so nearer and more frontal views
// rank higher), blended with the frame's median score over the buffer (region_weight: a
// region tends to keep one frame instead of a per-texel patchwork), and multiplied by
// edge_penalty where the texel is seen within edge_px of a depth discontinuity of the frame's
// depth map: near silhouettes a mesh a few pixels off samples the background (sky on a
// roof), so such samples fill texels no better view has painted and are replaced by the first
// that comes. A texel already painted takes the sample only when its score beats the stored
// one by switch_margin; the stage clears the others from the warped buffer and writes the
// scores as its quality, which the paint stage stores.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/core/camera.h"
#include "pipeline/core/project.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/paint/base_buffer.h"
#include "pipeline/paint/frame_warp.h"
#include "pipeline/paint/paint_update.h"

namespace fresco {

// Distance (pixels, CV_32F) from each pixel to the nearest depth discontinuity of `depth`
// (CV_32F camera z, +inf where no surface): neighbouring pixels whose depths differ by more
// than `depth_rel` times the nearer, or where surface meets no surface. Large everywhere
// when there is none.
cv::Mat DistanceToDepthEdges(const cv::Mat& depth, double depth_rel);

struct ViewSelectInputs {
  const Camera* camera = nullptr;
  Rigid3d cam_from_local;
  cv::Mat edge_distance_px;  // DistanceToDepthEdges of the frame (empty: no edge penalty)
};

struct ViewSelectStats {
  int candidates = 0;  // valid texels before selection
  int kept = 0;        // painted texels that keep their stored sample
  int near_edge = 0;   // valid texels seen near a depth discontinuity
  double median_score = 0;
};

// Scores buffer `buffer`'s valid texels in `warped` (its quality replaced by the scores) and
// clears those whose stored sample is better (stored quality in `painted`); `kept`, if given,
// becomes a CV_8U mask of the rectangle, 255 where a texel was cleared so.
ViewSelectStats SelectViews(const BaseBuffer& buffer, const ViewSelectInputs& inputs,
                            const SelectOptions& options, const PaintedBuffer& painted,
                            WarpedBuffer* warped, cv::Mat* kept = nullptr);

}  // namespace fresco
