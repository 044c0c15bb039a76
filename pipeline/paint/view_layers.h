// View-dependent layers (pipeline.layers): the base buffers' texels painted again, per layer,
// from only the frames that look at the scene from one direction, so that a render from a
// viewpoint can show what the frames taken nearby saw (sun, haze, gloss, the exposure of that
// side) where one texture shows a compromise of every frame. Layers are made as frames arrive
// (streaming: no clustering over the whole capture): a frame whose direction from the scene's
// centre is more than `min_angle_deg` from every layer's starts a new one; once there are
// `count`, the new one takes the place of the layer with fewer frames of the two nearest each
// other (its texels are in the base texture and the neighbour), so the layers stay spread over
// the directions seen. Otherwise the frame joins the nearest layer. The layers stage
// (layers_stage.cc) paints the frame's samples that the pipeline kept (visible, not masked as a
// mover) into its layer with the pipeline's update rule. Rendering blends them
// (pipeline/render/view_dependent_render.h).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "pipeline/settings/layers_options.h"
#include "pipeline/paint/texel_update.h"

namespace fresco {

struct ViewLayer {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  // unit, from the scene's centre (local)
  Eigen::Vector3d centre_sum = Eigen::Vector3d::Zero();  // its frames' camera centres (local)
  int frames = 0;
  std::vector<PaintedBuffer> painted;  // one per base buffer

  // The mean camera centre of its frames, in the scene's local coordinates.
  Eigen::Vector3d Centre() const {
    return frames > 0 ? Eigen::Vector3d(centre_sum / frames) : centre_sum;
  }
};

// Where a frame with camera centre `camera_centre` (local coordinates) goes: an existing layer,
// or a fresh one (`fresh`) at `index` (layers.size(): appended; below: in place of that layer)
// whose direction is `direction`. A camera at the scene's centre counts as looking along +z.
struct LayerChoice {
  size_t index = 0;
  bool fresh = false;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
};
LayerChoice ChooseViewLayer(const std::vector<ViewLayer>& layers,
                            const Eigen::Vector3d& scene_centre,
                            const Eigen::Vector3d& camera_centre, const ViewLayerOptions& options);

}  // namespace fresco
