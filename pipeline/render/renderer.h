// Renders a textured scene through a camera: colour (RGBA), depth and triangle id per pixel,
// at the camera's image size, deterministic and on the CPU. Texture lookup follows glTF:
// UV (0,0) is the top-left of the image, wrap modes per sampler, base-colour factor times
// texture. Alpha is 255 where a surface with texture alpha > 0 is seen, 0 elsewhere
// (unpainted texels of painted buffers have alpha 0, and their colours never bleed into
// painted neighbours).
#pragma once

#include <opencv2/core.hpp>

#include "pipeline/core/camera.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/scene.h"
#include "pipeline/render/rasterizer.h"

namespace fresco {

enum class TextureFilter { kNearest, kBilinear };

struct RenderOptions {
  RasterOptions raster;  // raster.supersample > 1 averages N x N samples per pixel
  TextureFilter filter = TextureFilter::kBilinear;
  cv::Vec4b background = cv::Vec4b(0, 0, 0, 0);  // RGBA where no surface
};

struct RenderOutput {
  cv::Mat rgba;         // CV_8UC4 (R,G,B,A order), camera size
  cv::Mat depth;        // CV_32F, camera size (centre sample), +inf where none
  cv::Mat triangle_id;  // CV_32S, camera size (centre sample), -1 where none
};

class Renderer {
 public:
  Renderer(const Camera& camera, const RenderOptions& options);
  void Render(const Scene& scene, const Rigid3d& cam_from_world, RenderOutput* output) const;
  const Rasterizer& rasterizer() const { return rasterizer_; }

 private:
  RenderOptions options_;
  Rasterizer rasterizer_;
};

// glTF texture lookup at UV with the texture's wrap modes; RGBA in [0,1].
Eigen::Vector4d SampleTexture(const Texture& texture, const Eigen::Vector2d& uv,
                              TextureFilter filter);

// cam_from_local for a scene: cam_from_world composed with world_from_local (translation by
// the scene's origin), in double.
Rigid3d CamFromLocal(const Scene& scene, const Rigid3d& cam_from_world);

}  // namespace fresco
