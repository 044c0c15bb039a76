// The 3D viewport on OpenGL 3.3 core: renders the model into an offscreen framebuffer with
// two outputs, colour and triangle id (for picking). Modes: painted textures (never-painted
// texels dimmed), groups in distinct colours, or the current frame projected onto the model
// through its camera (pinhole part of the lens: a preview). Lines: the camera path and the
// current frame's frustum. The model is drawn in the scene's local frame (map-scale safe).
#pragma once

#include <memory>

#include "ui/core/panel.h"

namespace fresco {

class GlViewport : public ViewportRenderer {
 public:
  GlViewport();
  ~GlViewport() override;
  ImTextureID Render(const RunnerSnapshot& snapshot, const AppState& state, ViewportView* view,
                     int width, int height) override;
  int Pick(int x, int y) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fresco
