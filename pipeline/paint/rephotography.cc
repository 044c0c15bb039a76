#include "pipeline/paint/rephotography.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>

#include "pipeline/core/image_metrics.h"

namespace fresco {

RephotoScore ScoreRephoto(const Renderer& renderer, const Scene& painted,
                          const Rigid3d& cam_from_world, const cv::Mat& frame_bgr) {
  RenderOutput out;
  renderer.Render(painted, cam_from_world, &out);
  cv::Mat alpha, rendered_bgr;
  cv::extractChannel(out.rgba, alpha, 3);
  cv::cvtColor(out.rgba, rendered_bgr, cv::COLOR_RGBA2BGR);
  const cv::Mat surface = out.triangle_id >= 0;
  const cv::Mat both = surface & (alpha == 255);
  RephotoScore score;
  score.pixels = cv::countNonZero(both);
  score.completeness =
      static_cast<double>(score.pixels) / std::max(1, cv::countNonZero(surface));
  if (score.pixels > 0) {
    score.psnr_db = PsnrDb(frame_bgr, rendered_bgr, both);
    score.one_minus_ncc = OneMinusNcc(frame_bgr, rendered_bgr, both);
  }
  return score;
}

}  // namespace fresco
