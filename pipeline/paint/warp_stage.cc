// The warp stage (paint_stages.h): every texel of the buffers in the frustum projected into
// the frame through the lens, tested (grazing, back-facing, occluded) and sampled (eq. 1-4,
// §3.2, §3.3) into the warped buffers the later stages read (frame_warp.h). When no stage
// between warp and paint looks at the samples, the warp paints them directly.
#include <chrono>
#include <string>

#include <opencv2/imgproc.hpp>

#include "pipeline/paint/paint_session.h"
#include "pipeline/paint/paint_stages.h"
#include "pipeline/paint/stage_clock.h"

namespace fresco {

void PaintSession::WarpStage(FrameWork* work) {
  const auto start = std::chrono::steady_clock::now();
  StageReport report;
  report.name = "warp";
  FrameView& view = work->view;
  view.camera = work->camera;
  view.cam_from_local = work->cam_from_local;
  view.centre_local = work->cam_from_local.Centre();
  view.frame_bgr = &work->frame->bgr;
  view.depth = options_.occlusion.enabled ? &depth_ : nullptr;
  view.bounds = CacheFor(*work->camera).bounds;
  if (options_.sampling == SamplingMode::kArea) {
    view.pyramid.push_back(work->frame->bgr);
    while (view.pyramid.size() < 6 && view.pyramid.back().cols > 16) {
      cv::Mat down;
      cv::pyrDown(view.pyramid.back(), down);
      view.pyramid.push_back(down);
    }
  }
  WarpOptions warp_options;
  warp_options.sampling = options_.sampling;
  warp_options.occlusion = options_.occlusion;
  long long in_view = 0, visible = 0, occluded = 0, grazing = 0, buffers_seen = 0;
  long long tested = 0, chunks_culled = 0;
  work->seen.assign(set_.buffers.size(), false);
  // Buffers whose bounds lie outside the view frustum are skipped whole (no work, not even
  // clearing their warped images: later stages look only at buffers seen).
  std::vector<size_t>& in_frustum = work->in_frustum;
  in_frustum.clear();
  const bool own_only = own_only_.load();  // sharded: only the shard's buffers (SetOwnBuffers)
  for (size_t b = 0; b < set_.buffers.size(); ++b)
    if ((!own_only || own_[b]) &&
        !BoundsOutsideView(set_.buffers[b].bounds_min, set_.buffers[b].bounds_max, view,
                           warp_options.near_m))
      in_frustum.push_back(b);
  // When no stage looks at the warped samples before the paint stage (paint_stages.h) and no
  // debug images are wanted, the warp paints them directly: the same texels, without writing
  // and reading back the warped images.
  work->paint_in_warp = !StagesReadWarpedSamples(options_) && !work->debug;
  TexelUpdateRule rule = TexelUpdateRule::From(options_);
  rule.held_out = work->held_out && rule.mean_too;  // as PaintBuffer takes it
  if (work->paint_in_warp && view.depth && !in_frustum.empty() &&
      options_.sampling == SamplingMode::kBilinear) {
    // One pair per texel instead of four depths; only in the depth's window's rows (the warp
    // reads no other: OwnBuffersWindow).
    DepthRange2x2(depth_, &depth_range_, depth_rows_[0], depth_rows_[1]);
    view.depth_range = &depth_range_;
  }
  work->paint_stats.assign(set_.buffers.size(), PaintUpdateStats());
  ForEachBuffer(in_frustum, false, [&](size_t b) {
    if (work->paint_in_warp)
      work->paint_stats[b] =
          WarpAndPaintBuffer(set_.buffers[b], view, warp_options, rule, &warped_[b], &painted_[b]);
    else
      WarpFrameToBuffer(set_.buffers[b], view, warp_options, &warped_[b]);
  });
  for (size_t b : in_frustum) {
    in_view += warped_[b].in_view;
    visible += warped_[b].visible;
    occluded += warped_[b].occluded;
    grazing += warped_[b].grazing;
    tested += warped_[b].texels_tested;
    chunks_culled += warped_[b].chunks_culled;
    if (warped_[b].visible > 0) {
      work->seen[b] = true;
      ++buffers_seen;
      if (work->debug) {
        cv::Mat warped(warped_[b].bgr.size(), CV_8UC3, cv::Scalar(64, 64, 64));  // unseen: grey
        warped_[b].bgr.copyTo(warped, warped_[b].valid);
        report.images["warped_b" + std::to_string(b)] = warped;
        report.images["visible_b" + std::to_string(b)] = warped_[b].valid.clone();
      }
    }
  }
  report.metrics["buffers_culled"] = static_cast<double>(set_.buffers.size() - in_frustum.size());
  report.metrics["texels_in_view"] = static_cast<double>(in_view);
  report.metrics["texels_visible"] = static_cast<double>(visible);
  report.metrics["texels_occluded"] = static_cast<double>(occluded);
  report.metrics["texels_grazing"] = static_cast<double>(grazing);
  report.metrics["buffers_seen"] = static_cast<double>(buffers_seen);
  report.metrics["texels_tested"] = static_cast<double>(tested);
  report.metrics["chunks_culled"] = static_cast<double>(chunks_culled);
  report.wall_ms = MsSince(start);
  work->report->stages.push_back(std::move(report));
}

}  // namespace fresco
