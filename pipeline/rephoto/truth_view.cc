#include "pipeline/rephoto/truth_view.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "pipeline/core/image_metrics.h"
#include "pipeline/render/view_dependent_render.h"

namespace fresco {
namespace {

// A sphere around the mover that holds all of it (a box's half-diagonal), with 5 % to spare
// for the frames' anti-aliased edges.
double HidingRadius(const MoverOptions& mover) {
  const double r =
      mover.shape == MoverShape::kBox ? mover.radius_m * std::sqrt(3.0) : mover.radius_m;
  return 1.05 * r;
}

bool HiddenByAMover(const Eigen::Vector3d& point_world, const SceneTruth& truth) {
  for (const PaintedFrameCentre& f : *truth.painted_frames) {
    for (const MoverOptions& m : *truth.movers) {
      if (SegmentNearPoint(f.centre_world, point_world, MoverCentreAt(m, f.frame), HidingRadius(m)))
        return true;
    }
  }
  return false;
}

cv::Mat Bgr(const RenderOutput& out) {
  cv::Mat bgr;
  cv::cvtColor(out.rgba, bgr, cv::COLOR_RGBA2BGR);
  return bgr;
}

}  // namespace

bool SegmentNearPoint(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                      const Eigen::Vector3d& centre, double radius) {
  const Eigen::Vector3d d = to - from;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0 ? std::clamp((centre - from).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (from + t * d - centre).squaredNorm() <= radius * radius;
}

TruthViewScore ScoreTruthView(const TruthViewInputs& in) {
  RenderOutput painted, clean;
  const SceneTruth& truth = *in.truth;
  RenderViewDependent(*in.painted_renderer, *in.painted, in.true_cam_from_world, &painted);
  truth.renderer->Render(*truth.scene, in.true_cam_from_world, &clean);
  const cv::Mat painted_bgr = Bgr(painted);
  cv::Mat clean_bgr = Bgr(clean);
  if (in.exposure_gain != 1.0) clean_bgr.convertTo(clean_bgr, CV_8U, in.exposure_gain);
  cv::Mat alpha;
  cv::extractChannel(painted.rgba, alpha, 3);
  const cv::Mat mask = (painted.triangle_id >= 0) & (alpha == 255) & (clean.triangle_id >= 0);

  TruthViewScore score;
  score.painted_pixels = cv::countNonZero(mask);
  if (score.painted_pixels == 0) return score;
  score.psnr_db = PsnrDb(painted_bgr, clean_bgr, mask);
  score.one_minus_ncc = OneMinusNcc(painted_bgr, clean_bgr, mask);
  if (!truth.movers || truth.movers->empty() || !truth.painted_frames) return score;

  cv::Mat diff;
  cv::absdiff(painted_bgr, clean_bgr, diff);
  const Rasterizer& rays = in.painted_renderer->rasterizer();
  const Rigid3d world_from_cam = in.true_cam_from_world.Inverse();
  for (int y = 0; y < mask.rows; ++y) {
    for (int x = 0; x < mask.cols; ++x) {
      if (!mask.at<uint8_t>(y, x)) continue;
      const cv::Vec3b d = diff.at<cv::Vec3b>(y, x);
      if (std::max({d[0], d[1], d[2]}) <= truth.leak_threshold) continue;
      const Eigen::Vector2d normalized = rays.Ray(x, y).cast<double>();
      if (!normalized.allFinite()) continue;
      const double z = painted.depth.at<float>(y, x);
      const Eigen::Vector3d point = world_from_cam * (z * normalized.homogeneous());
      score.region_error_pixels += HiddenByAMover(point, truth);
    }
  }
  if (truth.mover_texels) {
    RenderOutput movers;
    in.painted_renderer->Render(*truth.mover_texels, in.true_cam_from_world, &movers);
    cv::Mat shows;
    cv::extractChannel(movers.rgba, shows, 0);
    score.leak_pixels = cv::countNonZero((shows >= 128) & mask);
  }
  return score;
}

}  // namespace fresco
