// The depth stage (paint_stages.h): the model's depth map seen from the frame's camera, which
// the warp's occlusion test compares each texel with (§3.3). Off with occlusion.enabled false.
#include <algorithm>
#include <chrono>
#include <cmath>
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

// Exactly the same pose (the depth kept was rasterized at it).
bool SamePose(const Rigid3d& a, const Rigid3d& b) {
  return a.rotation.coeffs() == b.rotation.coeffs() && a.translation == b.translation;
}

}  // namespace

bool PaintSession::BufferImageBox(size_t b, const FrameView& view, double box[4]) const {
  const Camera& camera = *view.camera;
  if (camera.HasDistortion()) return false;
  const double cut_z = 0.5 * WarpOptions().near_m;
  const auto add = [&](const Eigen::Vector3d& in_cam) {
    Eigen::Vector2d pixel;
    if (!camera.Project(in_cam, &pixel)) return false;
    box[0] = std::min(box[0], pixel.x()), box[2] = std::max(box[2], pixel.x());
    box[1] = std::min(box[1], pixel.y()), box[3] = std::max(box[3], pixel.y());
    return true;
  };
  const Eigen::Vector3d& lo = set_.buffers[b].bounds_min;
  const Eigen::Vector3d& hi = set_.buffers[b].bounds_max;
  Eigen::Vector3d corner[8];
  for (int c = 0; c < 8; ++c)
    corner[c] =
        view.cam_from_local * Eigen::Vector3d((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(),
                                              (c & 4) ? hi.z() : lo.z());
  for (int c = 0; c < 8; ++c) {
    if (corner[c].z() >= cut_z && !add(corner[c])) return false;
    for (int bit = 1; bit < 8; bit <<= 1) {  // each edge once: from its corner without `bit`
      if (c & bit) continue;
      const Eigen::Vector3d& p = corner[c];
      const Eigen::Vector3d& q = corner[c | bit];
      if ((p.z() < cut_z) == (q.z() < cut_z)) continue;
      Eigen::Vector3d crossing = p + (cut_z - p.z()) / (q.z() - p.z()) * (q - p);
      crossing.z() = cut_z;
      if (!add(crossing)) return false;
    }
  }
  return true;
}

// A shard painting only its own buffers (SetOwnBuffers) reads the depth only where they
// project: the box of their BufferImageBox, with the pixels the occlusion test reads beside
// each texel's. Empty (the whole image) when one is not bounded by its box.
cv::Rect PaintSession::OwnBuffersWindow(const Camera& camera, const NormalizedBounds& bounds,
                                        const Rigid3d& cam_from_local) const {
  if (!own_only_.load() || camera.HasDistortion()) return cv::Rect();
  const double inf = std::numeric_limits<double>::infinity();
  double box[4] = {inf, inf, -inf, -inf};
  // Buffers the warp leaves out whole (outside the view) are not read: as warp_stage.cc.
  FrameView view;
  view.camera = &camera;
  view.cam_from_local = cam_from_local;
  view.bounds = bounds;
  const double near_m = WarpOptions().near_m;
  for (size_t b = 0; b < set_.buffers.size(); ++b)
    if (own_[b] &&
        !BoundsOutsideView(set_.buffers[b].bounds_min, set_.buffers[b].bounds_max, view, near_m) &&
        !BufferImageBox(b, view, box))
      return cv::Rect();
  const double x0 = box[0], y0 = box[1], x1 = box[2], y1 = box[3];
  if (!(x0 <= x1)) return cv::Rect(-4, -4, 1, 1);  // none: a window outside the image
  constexpr int kMargin = 4;                       // the 2x2 depths about a sample, and rounding
  return cv::Rect(cv::Point(static_cast<int>(std::floor(std::max(x0, -1e6))) - kMargin,
                            static_cast<int>(std::floor(std::max(y0, -1e6))) - kMargin),
                  cv::Point(static_cast<int>(std::ceil(std::min(x1, 1e6))) + kMargin + 1,
                            static_cast<int>(std::ceil(std::min(y1, 1e6))) + kMargin + 1));
}

void PaintSession::DepthStage(FrameWork* work) {
  const auto start = std::chrono::steady_clock::now();
  StageReport report;
  report.name = "depth";
  if (options_.occlusion.enabled) {
    const CameraCache& cache = CacheFor(*work->camera);
    cv::Rect window = OwnBuffersWindow(*work->camera, cache.bounds, work->cam_from_local);
    const Frame& frame = *work->frame;
    if (!frame.depth.empty() && frame.depth.type() == CV_32F &&
        frame.depth.size() == cv::Size(work->camera->width, work->camera->height) &&
        cache.rasterizer->options().supersample == 1 &&
        SamePose(frame.depth_cam_from_local, work->cam_from_local)) {
      frame.depth.copyTo(depth_);  // rasterized by the pre-pass: the same as below, whole
      window = cv::Rect();
    } else {
      cache.rasterizer->RasterizeDepth(scene_->mesh, work->cam_from_local, &depth_, window);
    }
    // The share of the image the depth was rasterized in (1: the whole image).
    const cv::Rect image(0, 0, work->camera->width, work->camera->height);
    depth_rows_[0] = 0, depth_rows_[1] = -1;
    if (!window.empty()) {
      // Exact there and a pixel about it (RasterizeDepth): so is each row's 2x2 range.
      const int n = cache.rasterizer->options().supersample;
      depth_rows_[0] = std::max(0, window.y * n), depth_rows_[1] = std::max(0, window.br().y * n);
    }
    report.metrics["window_fraction"] =
        window.empty() ? 1.0 : static_cast<double>((window & image).area()) / image.area();
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
