// Renders a textured scene through a camera: colour (RGBA), depth and triangle id per pixel,
// at the camera's image size, deterministic and on the CPU. Texture lookup follows glTF:
// UV (0,0) is the top-left of the image, texel centres at (i + 0.5) / size, wrap modes per
// sampler, base-colour factor times texture. Alpha is 255 where a surface with (filtered)
// alpha >= 0.5 is seen, 0 elsewhere (unpainted texels of painted buffers have alpha 0, and
// bilinear filtering weights taps by alpha, so their colours never bleed into painted
// neighbours). With N x N supersampling a pixel's alpha is 255 when the mean of its samples'
// alphas is >= 0.5, and its colour is the alpha-weighted mean of the samples' colours.
#pragma once

#include <memory>

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
  cv::Mat rgba;  // CV_8UC4 (R,G,B,A order), camera size
  // Depth and triangle id at the pixel centres: the centre sample for N = 1 or odd N, a
  // separate 1x rasterization for even N (no sample of an even grid is at the centre).
  cv::Mat depth;        // CV_32F, camera size (camera z, metres), +inf where none
  cv::Mat triangle_id;  // CV_32S, camera size, -1 where none
};

class Renderer {
 public:
  // Precomputes the ray table(s) for `camera` (throws std::invalid_argument on bad options).
  Renderer(const Camera& camera, const RenderOptions& options);
  ~Renderer();
  // Thread-safe (const): several threads may render with one Renderer.
  void Render(const Scene& scene, const Rigid3d& cam_from_world, RenderOutput* output) const;
  // Render's two halves, for scenes that differ only in their textures' pixels (one
  // rasterization shaded with each): the samples `scene` shows at `cam_from_world`, then
  // their colours (`rgba`: CV_8UC4, camera size), as Render's `rgba` to the bit.
  void RasterizeScene(const Scene& scene, const Rigid3d& cam_from_world,
                      RasterOutput* raster) const;
  void ShadeScene(const Scene& scene, const RasterOutput& raster, cv::Mat* rgba) const;
  const Rasterizer& rasterizer() const { return rasterizer_; }
  const RenderOptions& options() const { return options_; }

 private:
  RenderOptions options_;
  Rasterizer rasterizer_;                          // N x N samples per pixel
  std::unique_ptr<Rasterizer> centre_rasterizer_;  // 1x, only for even N
};

// glTF texture lookup at UV with the texture's wrap modes; RGBA in [0,1]. Bilinear weights
// each tap by its alpha (premultiplied) and returns the un-premultiplied colour with the
// filtered alpha (colour 0 where all taps have alpha 0). An empty texture gives (1,1,1,1).
Eigen::Vector4d SampleTexture(const Texture& texture, const Eigen::Vector2d& uv,
                              TextureFilter filter);

// cam_from_local for a scene: cam_from_world composed with world_from_local (translation by
// the scene's origin), in double.
Rigid3d CamFromLocal(const Scene& scene, const Rigid3d& cam_from_world);

}  // namespace fresco
