// A PaintSession's painting state (PaintSession::SaveState / RestoreState): a copy of every
// member that painting a frame changes, pixels included. Its images are packed (packed_image.h):
// the blocks all zero are not stored (a large model's texels never painted, the sums not made)
// and the blocks equal to the state saved before it are shared with it. What stays put while a
// session paints (the grouping, the buffers' layout, the atlas, the camera caches) is not in
// it. The current frame's work images (warped samples, masks) are: a stage may read what an
// earlier frame left outside the texels it sampled.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "pipeline/paint/packed_image.h"
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
  // Every image of the lists above, packed, in the order painting_state.cc walks them (the
  // lists hold them released).
  std::vector<PackedImage> images;
  size_t bytes = 0;  // held: the images' blocks stored (shared ones too), the models, the frames
  size_t block_bytes = 0;  // ... of which the images' blocks
  // Where the bytes go: each kind's images before packing and as held, and the models.
  struct Part {
    const char* what;
    size_t raw = 0, held = 0;
  };
  std::vector<Part> parts;

  // Each image block held (its identity, its bytes): blocks shared between states count once.
  template <typename F>
  void ForEachBlock(F f) const {
    for (const PackedImage& image : images) image.ForEachBlock(f);
  }
};

}  // namespace fresco
