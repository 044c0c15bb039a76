// Rendering a painted model with view-dependent layers (pipeline/paint/view_layers.h): per
// pixel, the layers that have paint there are blended by how close the direction from the
// surface point to each layer's cameras is to the direction to the viewer (unstructured
// lumigraph weights over the two nearest, the third nearest as the cut-off), so a view between
// two layers' cameras fades from one to the other and a view at a layer's cameras shows that
// layer. Where no layer has paint the base texture shows.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "pipeline/core/rigid3.h"
#include "pipeline/core/scene.h"
#include "pipeline/render/renderer.h"

namespace fresco {

struct ViewLayerScene {
  Scene scene;                   // the same geometry as the base, the layer's texture
  Eigen::Vector3d centre_world;  // the mean camera centre of the layer's frames (world)
};

// Renders `base` and every layer at `cam_from_world` and blends them into `output` (rgba; depth
// and triangle id those of the base render). With no layers, the base render.
void RenderViewDependent(const Renderer& renderer, const Scene& base,
                         const std::vector<ViewLayerScene>& layers, const Rigid3d& cam_from_world,
                         RenderOutput* output);

}  // namespace fresco
