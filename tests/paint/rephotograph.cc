#include "tests/paint/rephotograph.h"

#include <algorithm>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "pipeline/core/image_metrics.h"

namespace fresco::testing {

Rephoto Rephotograph(const Renderer& renderer, const Scene& original, const Scene& painted,
                     const Rigid3d& cam_from_world) {
  RenderOutput truth, paint;
  renderer.Render(original, cam_from_world, &truth);
  renderer.Render(painted, cam_from_world, &paint);
  std::vector<cv::Mat> t_ch, p_ch;
  cv::split(truth.rgba, t_ch);
  cv::split(paint.rgba, p_ch);
  const cv::Mat surface = t_ch[3] == 255;
  const cv::Mat both = surface & (p_ch[3] == 255);
  cv::Mat t_rgb, p_rgb;
  cv::cvtColor(truth.rgba, t_rgb, cv::COLOR_RGBA2RGB);
  cv::cvtColor(paint.rgba, p_rgb, cv::COLOR_RGBA2RGB);
  Rephoto r;
  r.psnr_db = PsnrDb(t_rgb, p_rgb, both);
  r.completeness =
      static_cast<double>(cv::countNonZero(both)) / std::max(1, cv::countNonZero(surface));
  return r;
}

Renderer RephotoRenderer(const Camera& camera) {
  RenderOptions options;
  options.raster.supersample = 2;
  return Renderer(camera, options);
}

}  // namespace fresco::testing
