#include "pipeline/paint/rephotography.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>

#include "pipeline/core/image_metrics.h"
#include "pipeline/render/view_dependent_render.h"

namespace fresco {

namespace {

// Scores a render; `both` and `rendered_bgr`: the compared pixels and the render.
RephotoScore Score(const RenderOutput& out, const cv::Mat& frame_bgr, cv::Mat* both_out,
                   cv::Mat* rendered_out) {
  cv::Mat alpha, rendered_bgr;
  cv::extractChannel(out.rgba, alpha, 3);
  cv::cvtColor(out.rgba, rendered_bgr, cv::COLOR_RGBA2BGR);
  const cv::Mat surface = out.triangle_id >= 0;
  const cv::Mat both = surface & (alpha == 255);
  *both_out = both;
  *rendered_out = rendered_bgr;
  RephotoScore score;
  score.pixels = cv::countNonZero(both);
  score.completeness = static_cast<double>(score.pixels) / std::max(1, cv::countNonZero(surface));
  if (score.pixels > 0) {
    score.psnr_db = PsnrDb(frame_bgr, rendered_bgr, both);
    score.one_minus_ncc = OneMinusNcc(frame_bgr, rendered_bgr, both);
  }
  return score;
}

}  // namespace

RephotoScore ScoreRephoto(const Renderer& renderer, const Scene& painted,
                          const Rigid3d& cam_from_world, const cv::Mat& frame_bgr) {
  RenderOutput out;
  RenderViewDependent(renderer, painted, cam_from_world, &out);
  cv::Mat both, rendered_bgr;
  return Score(out, frame_bgr, &both, &rendered_bgr);
}

RephotoScore ScoreRephoto(const Renderer& renderer, const Scene& painted,
                          const Rigid3d& cam_from_world, const cv::Mat& frame_bgr,
                          RephotoView* view) {
  RenderOutput out;
  RenderViewDependent(renderer, painted, cam_from_world, &out);
  const RephotoScore score = Score(out, frame_bgr, &view->compared, &view->rendered_bgr);
  view->rendered_bgr.setTo(cv::Scalar::all(0), view->compared == 0);
  view->local_one_minus_ncc =
      score.pixels > 0 ? LocalOneMinusNcc(frame_bgr, view->rendered_bgr, view->compared) : 0.0;
  view->image_coverage = static_cast<double>(score.pixels) / std::max<int>(1, frame_bgr.total());
  return score;
}

}  // namespace fresco
