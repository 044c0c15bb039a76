// Virtual rephotography for the painting tests: render the original and the painted model
// from the same pose and compare where both show a surface.
#pragma once

#include "pipeline/core/rigid3.h"
#include "pipeline/core/scene.h"
#include "pipeline/render/renderer.h"

namespace fresco::testing {

struct Rephoto {
  double psnr_db = 0;
  double completeness = 0;  // surface pixels of the original that the painted model covers
};

// `original` and `painted` rendered at `cam_from_world` as BGR, the original's surface pixels
// and those where both show a surface (CV_8U, 255).
struct TruthAndPainted {
  cv::Mat truth_bgr, painted_bgr, surface, both;
};
TruthAndPainted RenderTruthAndPainted(const Renderer& renderer, const Scene& original,
                                      const Scene& painted, const Rigid3d& cam_from_world);

// `renderer`: anti-aliased (supersample 2) like the synthetic frames.
Rephoto Rephotograph(const Renderer& renderer, const Scene& original, const Scene& painted,
                     const Rigid3d& cam_from_world);
// A renderer for Rephotograph through `camera`.
Renderer RephotoRenderer(const Camera& camera);

}  // namespace fresco::testing
