// The layers stage (paint_stages.h; view_layers.h), with pipeline.layers.count > 0: the frame
// joins the view-dependent layer of its direction from the scene's centre (or starts one), and
// its samples that the pipeline keeps (visible, not masked as movers) are painted into that
// layer with the pipeline's update rule. It runs before the select stage, which keeps only the
// samples that beat the base texture's: a layer keeps its own frames' best.
#include <chrono>
#include <string>

#include "pipeline/paint/paint_session.h"
#include "pipeline/paint/stage_clock.h"

namespace fresco {

void PaintSession::LayersStage(FrameWork* work) {
  if (options_.layers.count <= 0) return;
  const auto start = std::chrono::steady_clock::now();
  StageReport report;
  report.name = "layers";
  const Eigen::Vector3d camera_centre = work->cam_from_local.Centre();
  const LayerChoice choice =
      ChooseViewLayer(layers_, scene_centre_, camera_centre, options_.layers);
  const size_t k = choice.index;
  const bool replaced = choice.fresh && k < layers_.size();
  if (choice.fresh) {
    if (k == layers_.size()) layers_.emplace_back();
    ViewLayer& fresh = layers_[k];
    fresh.direction = choice.direction;
    fresh.centre_sum.setZero();
    fresh.frames = 0;
    fresh.painted.resize(set_.buffers.size());
    for (size_t b = 0; b < set_.buffers.size(); ++b)
      InitPaintedBuffer(set_.buffers[b], &fresh.painted[b]);
  }
  ViewLayer& layer = layers_[k];
  layer.centre_sum += camera_centre;
  ++layer.frames;
  const std::vector<size_t> seen = Indices(work->seen);
  std::vector<PaintUpdateStats> stats(set_.buffers.size());
  ForEachBuffer(seen, false, [&](size_t b) {
    stats[b] =
        PaintBuffer(set_.buffers[b], warped_[b], KeptOutOfPainting(b), options_, &layer.painted[b]);
  });
  long long written = 0;
  for (size_t b : seen) written += stats[b].written;
  report.metrics["layer"] = static_cast<double>(k);
  report.metrics["layers"] = static_cast<double>(layers_.size());
  report.metrics["layer_frames"] = static_cast<double>(layer.frames);
  report.metrics["texels_written"] = static_cast<double>(written);
  report.metrics["layer_replaced"] = replaced ? 1.0 : 0.0;
  report.notes["layer"] = std::string(replaced       ? "frame replaced layer "
                                      : choice.fresh ? "frame started layer "
                                                     : "frame joined layer ") +
                          std::to_string(k) + " of " + std::to_string(layers_.size()) + " (" +
                          std::to_string(layer.frames) + " frames)";
  report.wall_ms = MsSince(start);
  work->report->stages.push_back(std::move(report));
}

}  // namespace fresco
