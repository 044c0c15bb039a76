#include "tests/paint/rephotograph.h"

#include <algorithm>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "pipeline/core/image_metrics.h"

namespace fresco::testing {

TruthAndPainted RenderTruthAndPainted(const Renderer& renderer, const Scene& original,
                                      const Scene& painted, const Rigid3d& cam_from_world) {
  RenderOutput truth, paint;
  renderer.Render(original, cam_from_world, &truth);
  renderer.Render(painted, cam_from_world, &paint);
  std::vector<cv::Mat> t_ch, p_ch;
  cv::split(truth.rgba, t_ch);
  cv::split(paint.rgba, p_ch);
  TruthAndPainted out;
  out.surface = t_ch[3] == 255;
  out.both = out.surface & (p_ch[3] == 255);
  cv::cvtColor(truth.rgba, out.truth_bgr, cv::COLOR_RGBA2BGR);
  cv::cvtColor(paint.rgba, out.painted_bgr, cv::COLOR_RGBA2BGR);
  return out;
}

Rephoto Rephotograph(const Renderer& renderer, const Scene& original, const Scene& painted,
                     const Rigid3d& cam_from_world) {
  const TruthAndPainted r = RenderTruthAndPainted(renderer, original, painted, cam_from_world);
  Rephoto rephoto;
  rephoto.psnr_db = PsnrDb(r.truth_bgr, r.painted_bgr, r.both);  // channel order: same MSE
  rephoto.completeness =
      static_cast<double>(cv::countNonZero(r.both)) / std::max(1, cv::countNonZero(r.surface));
  return rephoto;
}

Renderer RephotoRenderer(const Camera& camera) {
  RenderOptions options;
  options.raster.supersample = 2;
  return Renderer(camera, options);
}

}  // namespace fresco::testing
