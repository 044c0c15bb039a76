// Model-based warping of one frame into a base buffer (paper eq. 1, 3, 4, §3.2, §3.3), fused
// in one per-texel kernel: project the texel's model point through the frame's camera (full
// lens model), reject back-facing and grazing views, keep it only if the video camera's
// depth map agrees with its depth (tolerance scaled with depth and view angle), and sample
// the frame (nearest, bilinear, or area: bilinear on the pyramid level matching the texel's
// footprint). Chunks of texels (base_buffer.h) outside the view frustum are skipped whole.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "pipeline/core/camera.h"
#include "pipeline/core/project.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/paint/base_buffer.h"
#include "pipeline/paint/texel_update.h"

namespace fresco {

// The image's extent on the normalized (z = 1) plane, slightly enlarged: a point whose
// x/z or y/z lies outside it cannot land in the image. For distorted lenses it comes from
// unprojecting the image border; `valid` is false when the border does not unproject (the
// lens folds inside the image), and then only the near plane culls.
struct NormalizedBounds {
  bool valid = false;
  float x_min = 0, x_max = 0, y_min = 0, y_max = 0;
};
NormalizedBounds ComputeNormalizedBounds(const Camera& camera);

// Per pixel (x, y) of a continuous CV_32F depth map, the least and greatest depth of its 2x2
// block (x..x+1, y..y+1), as CV_32FC2 of the same size (the last row and column: their own
// depth). The bilinear occlusion test (every one of the four depths within tolerance of the
// texel's) is the same test on the pair. Only rows [row0, row1) when given (row1 -1: to the
// last; the other rows left as they were).
void DepthRange2x2(const cv::Mat& depth, cv::Mat* range, int row0 = 0, int row1 = -1);

// What every buffer of one frame shares.
struct FrameView {
  const Camera* camera = nullptr;
  Rigid3d cam_from_local;
  Eigen::Vector3d centre_local = Eigen::Vector3d::Zero();  // camera centre, local coords
  const cv::Mat* frame_bgr = nullptr;                      // CV_8UC3, camera size
  const cv::Mat* depth = nullptr;  // CV_32F camera z per pixel, or null (no occlusion)
  // Optional, with `depth` (continuous): CV_32FC2, per pixel (x, y) the least and greatest
  // depth of pixels x..x+1 by y..y+1 (DepthRange2x2): the bilinear occlusion test reads one
  // pair instead of four depths.
  const cv::Mat* depth_range = nullptr;
  std::vector<cv::Mat> pyramid;    // level 0 = frame; filled for SamplingMode::kArea
  NormalizedBounds bounds;         // for chunk culling (computed when not valid)
};

struct WarpOptions {
  SamplingMode sampling = SamplingMode::kBilinear;
  OcclusionOptions occlusion;
  double near_m = 1e-3;
};

// The frame warped into one buffer's texel space (only the buffer's texels are written).
struct WarpedBuffer {
  cv::Mat bgr;      // CV_8UC3, buffer size (where not valid: 0 or an earlier frame's colour)
  cv::Mat valid;    // CV_8U, 255 where the texel was seen and sampled
  cv::Mat quality;  // CV_32F, pixels per texel (min(f s cos / z, 1)) where valid
  int in_view = 0;  // texels that project inside the image, in front, not grazing
  int visible = 0;  // ... and pass the occlusion test
  int occluded = 0;
  int grazing = 0;              // back-facing or beyond max_view_angle
  int chunks_culled = 0;        // chunks of texels skipped whole (outside the view frustum)
  long long texels_tested = 0;  // texels in chunks that were not culled
  cv::Rect valid_box;  // bounds every valid texel (empty when none); whoever writes `valid`
                       // keeps it so: the next warp clears only this box

  // Whether `chunk` may hold valid texels (its tile meets valid_box): later stages skip
  // the others whole.
  bool MayBeValid(const BaseBuffer::Chunk& chunk) const {
    return chunk.x0 < valid_box.br().x && valid_box.x < chunk.x1 &&
           chunk.y0 < valid_box.br().y && valid_box.y < chunk.y1;
  }
};

// True when the box (local coordinates) lies wholly behind the near plane or beyond one side
// of the view frustum: nothing in it can be seen.
bool BoundsOutsideView(const Eigen::Vector3d& bounds_min, const Eigen::Vector3d& bounds_max,
                       const FrameView& view, double near_m);

void WarpFrameToBuffer(const BaseBuffer& buffer, const FrameView& view,
                       const WarpOptions& options, WarpedBuffer* warped);

// The warp and the paint update in one pass, for frames where no stage looks at the warped
// samples between the two (no background model, no refinement, no debug images): each
// visible sample goes straight into `painted` by `rule`, with no warped images written or
// read back. Paints exactly what WarpFrameToBuffer then PaintBuffer (no mask) paint; sets
// only the counts of `counts` (its images and valid_box are left as they were).
PaintUpdateStats WarpAndPaintBuffer(const BaseBuffer& buffer, const FrameView& view,
                                    const WarpOptions& options, const TexelUpdateRule& rule,
                                    WarpedBuffer* counts, PaintedBuffer* painted);

}  // namespace fresco
