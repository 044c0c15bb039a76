// Rendering a painted model with view-dependent layers (Scene::view_layers, painted by
// pipeline/paint/view_layers.h): per pixel, the layers that have paint there are blended by how
// close the direction from the surface point to each layer's cameras is to the direction to the
// viewer (unstructured lumigraph weights over the two nearest, the third nearest as the cut-off),
// so a view between two layers' cameras fades from one to the other and a view at a layer's cameras
// shows that layer. Where no layer has paint the base texture shows.
#pragma once

#include "pipeline/core/rigid3.h"
#include "pipeline/core/scene.h"
#include "pipeline/render/renderer.h"

namespace fresco {

// Renders `scene` and each of its view layers at `cam_from_world` and blends them into `output`
// (rgba; depth and triangle id those of the scene's render). With no layers, Renderer::Render.
void RenderViewDependent(const Renderer& renderer, const Scene& scene,
                         const Rigid3d& cam_from_world, RenderOutput* output);

}  // namespace fresco
