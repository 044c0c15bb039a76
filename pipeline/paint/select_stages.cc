// The exposure and select stages (paint_stages.h; exposure_gain.h, view_select.h), with
// pipeline.select on: the frame's gain against what the buffers hold divided out, and a view
// score per texel so that painted texels keep a better stored sample.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "pipeline/paint/exposure_gain.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/paint/seam_levelling.h"
#include "pipeline/paint/stage_clock.h"
#include "pipeline/paint/view_select.h"

namespace fresco {

void PaintSession::ExposureStage(FrameWork* work) {
  if (SelectActive(options_) && options_.select.exposure)
    work->report->stages.push_back(CorrectExposure(Indices(work->seen)));
}

void PaintSession::SelectStage(FrameWork* work) {
  if (SelectActive(options_)) work->report->stages.push_back(SelectViewsStage(Indices(work->seen)));
}

StageReport PaintSession::CorrectExposure(const std::vector<size_t>& seen) {
  const auto start = std::chrono::steady_clock::now();
  StageReport report;
  report.name = "exposure";
  const ExposureGain gain = EstimateExposureGain(set_.buffers, warped_, painted_, seen);
  ApplyExposureGain(gain, seen, &warped_);
  exposure_gain_sum_ += gain.gain;
  exposure_offset_sum_ += gain.offset;
  ++exposure_frames_;
  report.metrics["gain_b"] = gain.gain[0];
  report.metrics["gain_g"] = gain.gain[1];
  report.metrics["gain_r"] = gain.gain[2];
  report.metrics["offset_b"] = gain.offset[0];
  report.metrics["offset_g"] = gain.offset[1];
  report.metrics["offset_r"] = gain.offset[2];
  report.metrics["samples"] = gain.samples;
  report.metrics["applied"] = gain.applied ? 1.0 : 0.0;
  report.wall_ms = MsSince(start);
  return report;
}

bool SelectActive(const PipelineOptions& options) {
  // refine.mode auto gives way to view selection (it decides off at once).
  return options.select.enabled &&
         (options.update == UpdatePolicy::kQuality || options.update == UpdatePolicy::kAuto) &&
         (options.refine.mode == RefineMode::kOff || options.refine.mode == RefineMode::kAuto);
}

int EffectiveWarmupFrames(const PaintSessionInputs& inputs) {
  const int warmup = inputs.pipeline.background.warmup_frames;
  const int frames = static_cast<int>(inputs.expected_poses.size());
  if (!SelectActive(inputs.pipeline) || frames == 0) return warmup;
  return std::min(warmup, std::max(2, frames / 3));
}

cv::Mat PaintSession::AtMeanExposure(const cv::Mat& bgra) const {
  if (exposure_frames_ == 0) return bgra;
  cv::Matx<float, 4, 5> mean =
      cv::Matx<float, 4, 5>::zeros();  // BGRA: the mean transform on B, G, R; alpha kept
  for (int c = 0; c < 3; ++c) {
    mean(c, c) = static_cast<float>(exposure_gain_sum_[c] / exposure_frames_);
    mean(c, 4) = static_cast<float>(exposure_offset_sum_[c] / exposure_frames_);
  }
  mean(3, 3) = 1;
  cv::Mat out;
  cv::transform(bgra, out, mean);  // rounded, saturated
  return out;
}

StageReport PaintSession::SelectViewsStage(const std::vector<size_t>& seen) {
  const auto start = std::chrono::steady_clock::now();
  StageReport report;
  report.name = "select";
  ViewSelectInputs inputs;
  inputs.camera = frame_camera_;
  inputs.cam_from_local = frame_cam_from_local_;
  if (options_.occlusion.enabled && options_.select.edge_px > 0)
    inputs.edge_distance_px = DistanceToDepthEdges(depth_, options_.select.edge_depth_rel);
  std::vector<ViewSelectStats> stats(set_.buffers.size());
  const bool level = options_.select.level_seams;
  std::vector<SeamLevelStats> level_stats(level ? set_.buffers.size() : 0);
  SeamLevelOptions level_options;
  level_options.cell_texels = options_.select.level_cell_texels;
  level_options.fade_texels = options_.select.level_cell_texels;
  ForEachBuffer(seen, false, [&](size_t b) {
    cv::Mat kept;  // the texels seen that keep their stored sample: the seams' other side
    stats[b] = SelectViews(set_.buffers[b], inputs, options_.select, painted_[b], &warped_[b],
                           level ? &kept : nullptr);
    if (level) level_stats[b] = LevelSeams(painted_[b], kept, level_options, &warped_[b]);
  });
  long long candidates = 0, kept = 0, near_edge = 0;
  for (size_t b : seen) {
    candidates += stats[b].candidates;
    kept += stats[b].kept;
    near_edge += stats[b].near_edge;
  }
  report.metrics["texels_candidate"] = static_cast<double>(candidates);
  report.metrics["texels_kept_better"] = static_cast<double>(kept);
  report.metrics["texels_near_edge"] = static_cast<double>(near_edge);
  if (level) {
    long long measured = 0, filled = 0;
    double abs_log = 0;
    for (size_t b : seen) {
      measured += level_stats[b].cells_measured, filled += level_stats[b].cells_filled;
      abs_log += level_stats[b].abs_log_sum;
    }
    report.metrics["level_cells_measured"] = static_cast<double>(measured);
    report.metrics["level_cells_filled"] = static_cast<double>(filled);
    // The mean correction over the measured cells, percent.
    report.metrics["level_mean_percent"] =
        measured > 0 ? 100.0 * (std::exp(abs_log / (3.0 * static_cast<double>(measured))) - 1.0)
                     : 0.0;
  }
  report.wall_ms = MsSince(start);
  return report;
}

}  // namespace fresco
