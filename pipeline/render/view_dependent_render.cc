#include "pipeline/render/view_dependent_render.h"

#include <algorithm>
#include <cmath>

#include <opencv2/core/utility.hpp>

namespace fresco {

void RenderViewDependent(const Renderer& renderer, const Scene& scene,
                         const Rigid3d& cam_from_world, RenderOutput* output) {
  renderer.Render(scene, cam_from_world, output);
  const std::vector<ViewLayerTextures>& layers = scene.view_layers;
  if (layers.empty()) return;
  // Each layer: the scene with its materials showing the layer's textures (transparent where
  // the layer has none).
  Scene layer_scene = scene;
  layer_scene.view_layers.clear();
  std::vector<cv::Mat> rgba(layers.size());
  for (size_t k = 0; k < layers.size(); ++k) {
    for (size_t m = 0; m < layer_scene.materials.size(); ++m) {
      const int t = m < layers[k].material_texture.size() ? layers[k].material_texture[m] : -1;
      layer_scene.materials[m] = scene.materials[m];
      layer_scene.materials[m].base_color_texture = t;
      if (t < 0) layer_scene.materials[m].base_color_factor[3] = 0;
    }
    RenderOutput out;
    renderer.Render(layer_scene, cam_from_world, &out);
    rgba[k] = out.rgba;
  }
  const Rigid3d world_from_cam = cam_from_world.Inverse();
  const Eigen::Vector3d viewer = world_from_cam.translation;
  const int n = renderer.options().raster.supersample;
  const Rasterizer& rays = renderer.rasterizer();
  const int rows = output->rgba.rows, cols = output->rgba.cols;
  cv::parallel_for_(cv::Range(0, rows), [&](const cv::Range& range) {
    std::vector<std::pair<double, size_t>> near;  // (angle, layer) of the layers painted here
    for (int y = range.start; y < range.end; ++y) {
      const float* depth = output->depth.ptr<float>(y);
      cv::Vec4b* out = output->rgba.ptr<cv::Vec4b>(y);
      for (int x = 0; x < cols; ++x) {
        if (!std::isfinite(depth[x])) continue;
        near.clear();
        for (size_t k = 0; k < layers.size(); ++k)
          if (rgba[k].at<cv::Vec4b>(y, x)[3] == 255) near.emplace_back(0.0, k);
        if (near.empty()) continue;
        // The surface point (world) from the pixel's ray (the centre sample of its N x N).
        const Eigen::Vector2f r = rays.Ray(x * n + n / 2, y * n + n / 2);
        if (!std::isfinite(r.x())) continue;
        const Eigen::Vector3d p =
            world_from_cam * (Eigen::Vector3d(r.x(), r.y(), 1.0) * static_cast<double>(depth[x]));
        const Eigen::Vector3d to_viewer = (viewer - p).normalized();
        for (auto& [angle, k] : near) {
          const double c = (layers[k].centre_world - p).normalized().dot(to_viewer);
          angle = std::acos(std::clamp(c, -1.0, 1.0));
        }
        std::sort(near.begin(), near.end());
        const double cut = near.size() > 2 ? near[2].first : 2.0 * near.back().first + 1e-3;
        double weights[2] = {0, 0}, sum = 0;
        const size_t m = std::min<size_t>(2, near.size());
        for (size_t i = 0; i < m; ++i) {
          weights[i] = std::max(0.0, 1.0 - near[i].first / cut) / std::max(near[i].first, 1e-4);
          sum += weights[i];
        }
        if (sum <= 0) weights[0] = sum = 1;  // equidistant: the nearest
        double rgb[3] = {0, 0, 0};
        for (size_t i = 0; i < m; ++i) {
          const cv::Vec4b& s = rgba[near[i].second].at<cv::Vec4b>(y, x);
          for (int c = 0; c < 3; ++c) rgb[c] += weights[i] / sum * s[c];
        }
        for (int c = 0; c < 3; ++c)
          out[x][c] = static_cast<uint8_t>(std::clamp(rgb[c] + 0.5, 0.0, 255.0));
        out[x][3] = 255;
      }
    }
  });
}

}  // namespace fresco
