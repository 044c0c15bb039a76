// Colour rendering on top of the rasterizer: per sample, barycentrics -> glTF UV -> texture
// (premultiplied by texel alpha, so unpainted texels never bleed) x base-colour factor; per
// pixel, the alpha-weighted mean of its N x N samples.
#include "pipeline/render/renderer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <opencv2/core/utility.hpp>

namespace fresco {

namespace {

// Texel index after the wrap mode, for a (possibly negative or >= size) index.
inline int WrapIndex(long long i, int size, TextureWrap wrap) {
  if (i >= 0 && i < size) return static_cast<int>(i);  // the common case: no division
  switch (wrap) {
    case TextureWrap::kClampToEdge:
      return i < 0 ? 0 : size - 1;
    case TextureWrap::kMirroredRepeat: {
      const long long period = 2LL * size;
      long long m = i % period;
      if (m < 0) m += period;
      return static_cast<int>(m < size ? m : period - 1 - m);
    }
    case TextureWrap::kRepeat:
    default: {
      // 32-bit division when it fits (about twice as fast as 64-bit).
      int m = i >= -(1LL << 30) && i < (1LL << 30) ? static_cast<int>(i) % size
                                                   : static_cast<int>(i % size);
      return m < 0 ? m + size : m;
    }
  }
}

// The index after `wrapped` (= WrapIndex(i)), i.e. WrapIndex(i + 1), cheaply when possible.
inline int NextWrapIndex(int wrapped, long long i, int size, TextureWrap wrap) {
  if (wrap == TextureWrap::kRepeat) return wrapped + 1 == size ? 0 : wrapped + 1;
  return WrapIndex(i + 1, size, wrap);
}

// Keeps texel coordinates in a range where floor() fits an int64 and the wrap is exact
// (finite but absurd UVs still sample something).
double SaneCoordinate(double s) {
  if (!std::isfinite(s)) return 0.0;
  return std::clamp(s, -1e12, 1e12);
}

// Samples `texture` at (u, v): writes the premultiplied colour (r a, g a, b a, a) in [0,1].
// `image` is texture.rgba, non-empty CV_8UC4.
inline void SamplePremultiplied(const Texture& texture, double u, double v, TextureFilter filter,
                                double out[4]) {
  const cv::Mat& image = texture.rgba;
  const int width = image.cols, height = image.rows;
  // Texel (i, j) has its centre at UV ((i + 0.5) / width, (j + 0.5) / height).
  const double s = SaneCoordinate(u * width);
  const double t = SaneCoordinate(v * height);
  constexpr double kInv255 = 1.0 / 255.0;
  if (filter == TextureFilter::kNearest) {
    const int i = WrapIndex(static_cast<long long>(std::floor(s)), width, texture.wrap_s);
    const int j = WrapIndex(static_cast<long long>(std::floor(t)), height, texture.wrap_t);
    const uchar* p = image.ptr<uchar>(j) + 4 * i;
    const double a = p[3] * kInv255;
    for (int k = 0; k < 3; ++k) out[k] = p[k] * kInv255 * a;
    out[3] = a;
    return;
  }
  const double fs = s - 0.5, ft = t - 0.5;
  const double s0 = std::floor(fs), t0 = std::floor(ft);
  const double ws = fs - s0, wt = ft - t0;
  const long long is = static_cast<long long>(s0), it = static_cast<long long>(t0);
  const int i0 = WrapIndex(is, width, texture.wrap_s);
  const int i1 = NextWrapIndex(i0, is, width, texture.wrap_s);
  const int j0 = WrapIndex(it, height, texture.wrap_t);
  const int j1 = NextWrapIndex(j0, it, height, texture.wrap_t);
  const uchar* row0 = image.ptr<uchar>(j0);
  const uchar* row1 = image.ptr<uchar>(j1);
  const uchar* taps[4] = {row0 + 4 * i0, row0 + 4 * i1, row1 + 4 * i0, row1 + 4 * i1};
  const double weights[4] = {(1 - ws) * (1 - wt), ws * (1 - wt), (1 - ws) * wt, ws * wt};
  // Premultiplied: each tap's colour counts by its weight times its alpha, so the colours of
  // alpha-0 texels never bleed into their neighbours.
  double r = 0, g = 0, b = 0, alpha = 0;
  for (int k = 0; k < 4; ++k) {
    const uchar* p = taps[k];
    const double wa = weights[k] * p[3];
    r += wa * p[0];
    g += wa * p[1];
    b += wa * p[2];
    alpha += wa;
  }
  constexpr double kInv255Squared = kInv255 * kInv255;
  out[0] = r * kInv255Squared;
  out[1] = g * kInv255Squared;
  out[2] = b * kInv255Squared;
  out[3] = alpha * kInv255;
}

bool UsableTexture(const Texture& texture) {
  return !texture.rgba.empty() && texture.rgba.type() == CV_8UC4;
}

// Depth and triangle id at the centres of the pixels (`size`), from the n x n samples'
// raster (odd n: sample (n-1)/2 of each pixel is its centre) or from `centre` (even n: a 1x
// rasterization).
void CentreDepth(const RasterOutput& raster, int n, const RasterOutput* centre, cv::Size size,
                 RenderOutput* output) {
  if (n == 1) {
    output->depth = raster.depth;
    output->triangle_id = raster.triangle_id;
    return;
  }
  if (centre) {
    output->depth = centre->depth;
    output->triangle_id = centre->triangle_id;
    return;
  }
  const int height = size.height, width = size.width;
  output->depth.create(height, width, CV_32F);
  output->triangle_id.create(height, width, CV_32S);
  const int c = (n - 1) / 2;
  for (int r = 0; r < height; ++r) {
    for (int col = 0; col < width; ++col) {
      output->depth.at<float>(r, col) = raster.depth.at<float>(r * n + c, col * n + c);
      output->triangle_id.at<int>(r, col) = raster.triangle_id.at<int>(r * n + c, col * n + c);
    }
  }
}

// A material's factor (alpha clamped to [0,1]) and its texture, if usable.
struct Shade {
  double factor[4];
  const Texture* texture;
};

// Per triangle: its material's shade, and whether its texture is sampled (it has UVs).
struct TriangleShades {
  std::vector<Shade> shades;  // per material, the last: default white
  std::vector<const Shade*> shade_of;
  std::vector<uint8_t> textured;
};

TriangleShades ShadesOf(const Scene& scene) {
  const TriangleMesh& mesh = scene.mesh;
  TriangleShades out;
  std::vector<Shade>& shades = out.shades;
  shades.resize(scene.materials.size() + 1);
  for (size_t m = 0; m < shades.size(); ++m) {
    const Material material = m < scene.materials.size() ? scene.materials[m] : Material();
    Shade& shade = shades[m];
    for (int k = 0; k < 4; ++k) shade.factor[k] = material.base_color_factor[k];
    shade.factor[3] = std::clamp(shade.factor[3], 0.0, 1.0);
    if (!std::isfinite(shade.factor[3])) shade.factor[3] = 0.0;
    const int t = material.base_color_texture;
    shade.texture =
        t >= 0 && t < static_cast<int>(scene.textures.size()) && UsableTexture(scene.textures[t])
            ? &scene.textures[t]
            : nullptr;
  }
  const int num_triangles = mesh.NumTriangles();
  out.shade_of.resize(num_triangles);
  out.textured.resize(num_triangles);
  for (int tri = 0; tri < num_triangles; ++tri) {
    const int m = tri < static_cast<int>(mesh.material.size()) ? mesh.material[tri] : -1;
    out.shade_of[tri] =
        &shades[m >= 0 && m < static_cast<int>(scene.materials.size()) ? m
                                                                       : scene.materials.size()];
    out.textured[tri] = out.shade_of[tri]->texture && tri < static_cast<int>(mesh.has_uv.size()) &&
                        mesh.has_uv[tri] && tri < static_cast<int>(mesh.uvs.size());
  }
  return out;
}

// Shading, one output row per task: per sample, alpha a = texture alpha x factor alpha and
// premultiplied colour a x texture colour x factor colour; per pixel, the sums' ratio.
void ShadePixels(const RasterOutput& raster, const TriangleMesh& mesh,
                 const TriangleShades& shading, const RenderOptions& options, cv::Mat* rgba) {
  const std::vector<const Shade*>& shade_of = shading.shade_of;
  const std::vector<uint8_t>& textured = shading.textured;
  const int n = options.raster.supersample;
  const int height = rgba->rows, width = rgba->cols;
  const TextureFilter filter = options.filter;
  const double inv_samples = 1.0 / (n * n);
  cv::parallel_for_(cv::Range(0, height), [&](const cv::Range& range) {
    for (int r = range.start; r < range.end; ++r) {
      cv::Vec4b* out = rgba->ptr<cv::Vec4b>(r);
      for (int col = 0; col < width; ++col) {
        double sum[4] = {0, 0, 0, 0};  // premultiplied colour, alpha
        for (int sr = r * n; sr < (r + 1) * n; ++sr) {
          const int* ids = raster.triangle_id.ptr<int>(sr);
          const cv::Vec2f* bary = raster.bary.ptr<cv::Vec2f>(sr);
          for (int sc = col * n; sc < (col + 1) * n; ++sc) {
            const int tri = ids[sc];
            if (tri < 0) continue;
            const Shade& shade = *shade_of[tri];
            double sample[4] = {1, 1, 1, 1};
            if (textured[tri]) {
              const auto& uv = mesh.uvs[tri];
              const double b1 = bary[sc][0], b2 = bary[sc][1], b0 = 1.0 - b1 - b2;
              const double u = b0 * uv[0].x() + b1 * uv[1].x() + b2 * uv[2].x();
              const double v = b0 * uv[0].y() + b1 * uv[1].y() + b2 * uv[2].y();
              SamplePremultiplied(*shade.texture, u, v, filter, sample);
            }
            for (int k = 0; k < 3; ++k) sum[k] += sample[k] * shade.factor[k] * shade.factor[3];
            sum[3] += sample[3] * shade.factor[3];
          }
        }
        if (sum[3] * inv_samples >= 0.5) {
          const double inv_alpha = 1.0 / sum[3];
          for (int k = 0; k < 3; ++k)
            out[col][k] =
                cv::saturate_cast<uchar>(std::clamp(sum[k] * inv_alpha, 0.0, 1.0) * 255.0);
          out[col][3] = 255;
        } else {
          out[col] = options.background;
        }
      }
    }
  });
}

}  // namespace

Eigen::Vector4d SampleTexture(const Texture& texture, const Eigen::Vector2d& uv,
                              TextureFilter filter) {
  if (!UsableTexture(texture)) return Eigen::Vector4d::Ones();
  double premultiplied[4];
  SamplePremultiplied(texture, uv.x(), uv.y(), filter, premultiplied);
  const double alpha = premultiplied[3];
  if (alpha <= 0.0) return Eigen::Vector4d::Zero();
  return Eigen::Vector4d(premultiplied[0] / alpha, premultiplied[1] / alpha,
                         premultiplied[2] / alpha, alpha);
}

Rigid3d CamFromLocal(const Scene& scene, const Rigid3d& cam_from_world) {
  const Rigid3d world_from_local(Eigen::Quaterniond::Identity(), scene.origin_in_world);
  return cam_from_world * world_from_local;
}

Renderer::Renderer(const Camera& camera, const RenderOptions& options)
    : options_(options), rasterizer_(camera, options.raster) {
  const int n = options.raster.supersample;
  if (n > 1 && n % 2 == 0) {
    // No sample of an even grid sits on the pixel centre: depth and triangle id come from
    // a separate 1x rasterization.
    RasterOptions centre = options.raster;
    centre.supersample = 1;
    centre_rasterizer_ = std::make_unique<Rasterizer>(camera, centre);
  }
}

Renderer::~Renderer() = default;

void Renderer::Render(const Scene& scene, const Rigid3d& cam_from_world,
                      RenderOutput* output) const {
  const Rigid3d cam_from_local = CamFromLocal(scene, cam_from_world);
  const TriangleMesh& mesh = scene.mesh;
  RasterOutput raster;
  rasterizer_.Rasterize(mesh, cam_from_local, &raster);
  const Camera& camera = rasterizer_.camera();
  const cv::Size size(camera.width, camera.height);
  const int n = options_.raster.supersample;
  if (n > 1 && centre_rasterizer_) {
    RasterOutput centre;
    centre_rasterizer_->Rasterize(mesh, cam_from_local, &centre);
    CentreDepth(raster, n, &centre, size, output);
  } else {
    CentreDepth(raster, n, nullptr, size, output);
  }
  ShadeScene(scene, raster, &output->rgba);
}

void Renderer::RasterizeScene(const Scene& scene, const Rigid3d& cam_from_world,
                              RasterOutput* raster) const {
  rasterizer_.Rasterize(scene.mesh, CamFromLocal(scene, cam_from_world), raster);
}

void Renderer::ShadeScene(const Scene& scene, const RasterOutput& raster, cv::Mat* rgba) const {
  const Camera& camera = rasterizer_.camera();
  rgba->create(cv::Size(camera.width, camera.height), CV_8UC4);
  ShadePixels(raster, scene.mesh, ShadesOf(scene), options_, rgba);
}

}  // namespace fresco
