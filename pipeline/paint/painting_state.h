// A PaintSession's painting state (PaintSession::SaveState / RestoreState): a deep copy of
// every member that painting a frame changes, pixels included (cv::Mat copies share pixels,
// so each is cloned). What stays put while a session paints (the grouping, the buffers'
// layout, the atlas, the camera caches) is not in it. The current frame's work images
// (warped samples, masks) are: a stage may read what an earlier frame left outside the texels
// it sampled.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "pipeline/paint/paint_session.h"

namespace fresco {

struct PaintSession::State {
  PipelineOptions options;  // `auto` modes resolve into it
  AutoDecision update_auto;
  std::vector<HeldOutFrame> update_held_out;
  bool model_decided_early = false;
  RefineAutoDecider refine_auto;
  BackgroundAutoDecider background_auto;
  std::pair<double, int> background_across_views{0.0, -1};
  bool own_only = false;
  int frames_painted_whole = 0;
  std::vector<PaintedBuffer> painted;
  std::vector<WarpedBuffer> warped, movers_warped;
  std::vector<cv::Mat> mover_texels, agreed_texels, near_mover_texels;
  std::vector<RefineAnchor> anchors;
  std::vector<ViewLayer> layers;
  std::vector<std::vector<BufferBackground>> background;
  std::vector<BackgroundFrame> background_frame;
  int frames_seen = 0;
  cv::Vec3d exposure_gain_sum, exposure_offset_sum;
  int exposure_frames = 0;
  double frame_misalignment_px = -1, frame_explained_px = -1;
  size_t bytes = 0;  // the pixels and models held
};

}  // namespace fresco
