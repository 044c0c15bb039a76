// The depth stage (paint_stages.h): the model's depth map seen from the frame's camera, which
// the warp's occlusion test compares each texel with (§3.3). Off with occlusion.enabled false.
#include <chrono>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "pipeline/paint/paint_session.h"
#include "pipeline/paint/stage_clock.h"

namespace fresco {
namespace {

// Near surfaces bright, far ones dark, no surface black.
cv::Mat DepthDebugImage(const cv::Mat& depth) {
  cv::Mat finite = depth.clone();
  cv::Mat mask = depth < 1e30f;
  double lo = 0, hi = 1;
  cv::minMaxLoc(depth, &lo, &hi, nullptr, nullptr, mask);
  finite.setTo(hi, ~mask);
  cv::Mat gray;
  finite.convertTo(gray, CV_8U, hi > lo ? -255.0 / (hi - lo) : 0,
                   hi > lo ? 255.0 * hi / (hi - lo) : 0);
  cv::Mat colour;
  cv::applyColorMap(gray, colour, cv::COLORMAP_VIRIDIS);
  colour.setTo(cv::Scalar(0, 0, 0), ~mask);
  return colour;
}

}  // namespace

void PaintSession::DepthStage(FrameWork* work) {
  const auto start = std::chrono::steady_clock::now();
  StageReport report;
  report.name = "depth";
  if (options_.occlusion.enabled) {
    CacheFor(*work->camera).rasterizer->RasterizeDepth(scene_->mesh, work->cam_from_local, &depth_);
    if (work->debug) {
      report.metrics["surface_pixels"] =
          cv::countNonZero(depth_ < std::numeric_limits<float>::infinity());
      report.images["depth"] = DepthDebugImage(depth_);
    }
  }
  report.wall_ms = MsSince(start);
  work->report->stages.push_back(std::move(report));
}

}  // namespace fresco
