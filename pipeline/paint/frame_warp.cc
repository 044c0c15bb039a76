#include "pipeline/paint/frame_warp.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <opencv2/core/utility.hpp>

namespace fresco {
namespace {

// A float copy of the camera for the hot loop (local coordinates keep values small, so
// float is ample: 1e-4 px at 1280 px). The same formulas as Camera::Project.
struct Projector {
  float fx, fy, cx, cy, k1, k2, k3, k4, k5, k6, p1, p2, fold_r2;
  explicit Projector(const Camera& c)
      : fx(c.fx),
        fy(c.fy),
        cx(c.cx),
        cy(c.cy),
        k1(c.k1),
        k2(c.k2),
        k3(c.k3),
        k4(c.k4),
        k5(c.k5),
        k6(c.k6),
        p1(c.p1),
        p2(c.p2),
        fold_r2(std::isfinite(c.fold_r2) ? static_cast<float>(c.fold_r2)
                                         : std::numeric_limits<float>::infinity()) {}

  // `p` in the camera frame with p.z > 0. False beyond the lens's fold.
  template <bool kDistorted>
  inline bool Project(const Eigen::Vector3f& p, float* u, float* v) const {
    const float inv_z = 1.0f / p.z();
    const float x = p.x() * inv_z, y = p.y() * inv_z;
    if constexpr (!kDistorted) {
      *u = fx * x + cx;
      *v = fy * y + cy;
      return true;
    } else {
      const float r2 = x * x + y * y;
      const float num = 1.0f + r2 * (k1 + r2 * (k2 + r2 * k3));
      const float den = 1.0f + r2 * (k4 + r2 * (k5 + r2 * k6));
      const float f = num / den;
      const float two_xy = 2.0f * x * y;
      *u = fx * (x * f + p1 * two_xy + p2 * (r2 + 2.0f * x * x)) + cx;
      *v = fy * (y * f + p1 * (r2 + 2.0f * y * y) + p2 * two_xy) + cy;
      return r2 <= fold_r2;
    }
  }
};

inline void SampleBilinear(const cv::Mat& img, float u, float v, uint8_t out[3]) {
  const int x0 = std::clamp(static_cast<int>(u), 0, img.cols - 1);
  const int y0 = std::clamp(static_cast<int>(v), 0, img.rows - 1);
  const int x1 = std::min(x0 + 1, img.cols - 1), y1 = std::min(y0 + 1, img.rows - 1);
  const float fx = std::clamp(u - x0, 0.0f, 1.0f), fy = std::clamp(v - y0, 0.0f, 1.0f);
  const uint8_t* r0 = img.data + y0 * img.step[0];
  const uint8_t* r1 = img.data + y1 * img.step[0];
  const float w00 = (1 - fx) * (1 - fy), w10 = fx * (1 - fy), w01 = (1 - fx) * fy, w11 = fx * fy;
  float rgb[3];
  for (int c = 0; c < 3; ++c)
    rgb[c] = w00 * r0[3 * x0 + c] + w10 * r0[3 * x1 + c] + w01 * r1[3 * x0 + c] +
             w11 * r1[3 * x1 + c] + 0.5f;
  out[0] = static_cast<uint8_t>(rgb[0]);
  out[1] = static_cast<uint8_t>(rgb[1]);
  out[2] = static_cast<uint8_t>(rgb[2]);
}

struct Counts {
  int in_view = 0, visible = 0, occluded = 0, grazing = 0, culled = 0;
  long long tested = 0;
};

// Everything the kernel needs, resolved once per buffer and frame.
struct KernelContext {
  const BaseBuffer* buffer;
  const Eigen::Vector3f* normals;
  Eigen::Matrix3f R;
  Eigen::Vector3f t, centre;
  Projector projector;
  NormalizedBounds bounds;
  float near_m, cos_max, max_u, max_v, focal, tol_rel, tol_abs;
  float slope_px;     // 1.5 / focal: the occlusion tolerance's slope term per unit tan
  float focal_texel;  // focal * texel size: pixels per texel at z = 1 m, head-on
  const cv::Mat* frame;
  const cv::Mat* depth;
  const std::vector<cv::Mat>* pyramid;
  uint8_t* out_bgr;
  uint8_t* out_valid;
  float* out_quality;
};

// True when the chunk's bounding box lies wholly behind the near plane or outside one side
// of the view frustum (all eight corners outside the same plane).
bool ChunkCulled(const KernelContext& k, const BaseBuffer::Chunk& chunk) {
  int behind = 0, left = 0, right = 0, top = 0, bottom = 0;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3f corner((c & 1) ? chunk.bounds_max.x() : chunk.bounds_min.x(),
                                 (c & 2) ? chunk.bounds_max.y() : chunk.bounds_min.y(),
                                 (c & 4) ? chunk.bounds_max.z() : chunk.bounds_min.z());
    const Eigen::Vector3f p = k.R * corner + k.t;
    behind += p.z() <= k.near_m;
    left += p.x() < k.bounds.x_min * p.z();
    right += p.x() > k.bounds.x_max * p.z();
    top += p.y() < k.bounds.y_min * p.z();
    bottom += p.y() > k.bounds.y_max * p.z();
  }
  if (behind == 8) return true;
  return k.bounds.valid && (left == 8 || right == 8 || top == 8 || bottom == 8);
}

// The kernel works on local copies of everything it reads: its outputs are written through
// byte pointers, which may alias anything, so fields read through references would be
// reloaded for every texel.
template <bool kDistorted, SamplingMode kMode, bool kDepth>
void WarpChunk(const KernelContext& context, const BaseBuffer::Chunk& chunk, Counts* counts) {
  const KernelContext k = context;
  const Eigen::Vector3f* const point = k.buffer->point.data();
  const int32_t* const triangle = k.buffer->triangle.data();
  const int32_t* const texel_index = k.buffer->texel_index.data();
  const float texel_size_m = static_cast<float>(k.buffer->texel_size_m);
  const uint8_t* const frame = k.frame->data;
  const size_t frame_step = k.frame->step[0];
  const uint8_t* const depth = k.depth->data;
  const size_t depth_step = k.depth->step[0];
  const int last_col = k.depth->cols - 1, last_row = k.depth->rows - 1;
  const int levels = static_cast<int>(k.pyramid->size());
  const float cos2_max = k.cos_max > 0.0f ? k.cos_max * k.cos_max : 0.0f;
  auto depth_at = [&](int x, int y) {
    return reinterpret_cast<const float*>(depth + y * depth_step)[x];
  };
  int in_view = 0, visible = 0, occluded = 0, grazing = 0;
  for (int i = chunk.begin; i < chunk.end; ++i) {
    const Eigen::Vector3f X = point[i];
    const Eigen::Vector3f p = k.R * X + k.t;
    if (!(p.z() > k.near_m)) continue;
    // Back-facing or grazing: n.d <= |d| cos_max, tested without a square root.
    const Eigen::Vector3f d = k.centre - X;
    const float nd = k.normals[triangle[i]].dot(d);
    const float dd = d.squaredNorm();
    if (nd <= 0.0f || nd * nd < cos2_max * dd) {
      ++grazing;
      continue;
    }
    float u, v;
    if (!k.projector.Project<kDistorted>(p, &u, &v)) continue;
    if (!(u >= 0.0f && v >= 0.0f && u <= k.max_u && v <= k.max_v)) continue;
    ++in_view;
    const float z = p.z();
    if constexpr (kDepth) {
      // Tolerance: relative + absolute, plus the depth change across 1.5 pixels at this
      // slope (tan of the view angle = |n x d| / n.d, and nd > 0 here).
      const float tan_view = std::sqrt(std::max(0.0f, dd - nd * nd)) / nd;
      const float tol = z * (k.tol_rel + k.slope_px * tan_view) + k.tol_abs;
      bool ok;
      if constexpr (kMode == SamplingMode::kNearest) {
        ok = std::abs(depth_at(static_cast<int>(u + 0.5f), static_cast<int>(v + 0.5f)) - z) <= tol;
      } else {
        const int x0 = static_cast<int>(u), y0 = static_cast<int>(v);
        const int x1 = std::min(x0 + 1, last_col), y1 = std::min(y0 + 1, last_row);
        ok = std::abs(depth_at(x0, y0) - z) <= tol && std::abs(depth_at(x1, y0) - z) <= tol &&
             std::abs(depth_at(x0, y1) - z) <= tol && std::abs(depth_at(x1, y1) - z) <= tol;
      }
      if (!ok) {
        ++occluded;
        continue;
      }
    }
    ++visible;
    const int idx = texel_index[i];
    uint8_t* out = k.out_bgr + 3 * static_cast<size_t>(idx);
    if constexpr (kMode == SamplingMode::kNearest) {
      const uint8_t* src =
          frame + static_cast<int>(v + 0.5f) * frame_step + 3 * static_cast<int>(u + 0.5f);
      out[0] = src[0], out[1] = src[1], out[2] = src[2];
    } else if constexpr (kMode == SamplingMode::kBilinear) {
      SampleBilinear(*k.frame, u, v, out);
    } else {
      // Area: bilinear on the pyramid level whose pixels match the texel's footprint.
      const float footprint = k.focal * texel_size_m / z;
      const int level = std::clamp(
          static_cast<int>(std::floor(std::log2(std::max(footprint, 1.0f)))), 0, levels - 1);
      const float scale = 1.0f / static_cast<float>(1 << level);
      SampleBilinear(levels > 0 ? (*k.pyramid)[level] : *k.frame, (u + 0.5f) * scale - 0.5f,
                     (v + 0.5f) * scale - 0.5f, out);
    }
    k.out_valid[idx] = 255;
    // Pixels per texel: f s cos(view) / z.
    k.out_quality[idx] = std::min(1.0f, k.focal_texel * nd / (std::sqrt(dd) * z));
  }
  counts->in_view += in_view, counts->visible += visible;
  counts->occluded += occluded, counts->grazing += grazing;
}

using ChunkKernel = void (*)(const KernelContext&, const BaseBuffer::Chunk&, Counts*);

template <bool kDistorted, bool kDepth>
ChunkKernel SelectForMode(SamplingMode mode) {
  switch (mode) {
    case SamplingMode::kNearest:
      return &WarpChunk<kDistorted, SamplingMode::kNearest, kDepth>;
    case SamplingMode::kArea:
      return &WarpChunk<kDistorted, SamplingMode::kArea, kDepth>;
    default:
      return &WarpChunk<kDistorted, SamplingMode::kBilinear, kDepth>;
  }
}

ChunkKernel SelectKernel(bool distorted, bool depth, SamplingMode mode) {
  if (distorted) return depth ? SelectForMode<true, true>(mode) : SelectForMode<true, false>(mode);
  return depth ? SelectForMode<false, true>(mode) : SelectForMode<false, false>(mode);
}

}  // namespace

NormalizedBounds ComputeNormalizedBounds(const Camera& camera) {
  NormalizedBounds b;
  b.x_min = b.y_min = std::numeric_limits<float>::max();
  b.x_max = b.y_max = -std::numeric_limits<float>::max();
  const int steps = 32;
  for (int s = 0; s <= steps; ++s) {
    const double a = static_cast<double>(s) / steps;
    const Eigen::Vector2d border[4] = {{a * (camera.width - 1), 0.0},
                                       {a * (camera.width - 1), camera.height - 1.0},
                                       {0.0, a * (camera.height - 1)},
                                       {camera.width - 1.0, a * (camera.height - 1)}};
    for (const Eigen::Vector2d& px : border) {
      Eigen::Vector2d n;
      if (!camera.Unproject(px, &n, 1e-3)) return NormalizedBounds();
      b.x_min = std::min(b.x_min, static_cast<float>(n.x()));
      b.x_max = std::max(b.x_max, static_cast<float>(n.x()));
      b.y_min = std::min(b.y_min, static_cast<float>(n.y()));
      b.y_max = std::max(b.y_max, static_cast<float>(n.y()));
    }
  }
  // The border's extreme need not be at a sample (barrel distortion bulges): 10 % margin.
  const float mx = 0.1f * (b.x_max - b.x_min), my = 0.1f * (b.y_max - b.y_min);
  b.x_min -= mx, b.x_max += mx, b.y_min -= my, b.y_max += my;
  b.valid = true;
  return b;
}

void WarpFrameToBuffer(const BaseBuffer& buffer,
                       const std::vector<Eigen::Vector3f>& triangle_normals, const FrameView& view,
                       const WarpOptions& options, WarpedBuffer* warped) {
  const int w = buffer.width, h = buffer.height;
  if (warped->bgr.rows != h || warped->bgr.cols != w) {
    warped->bgr.create(h, w, CV_8UC3);
    warped->valid.create(h, w, CV_8U);
    warped->quality.create(h, w, CV_32F);
  }
  warped->valid.setTo(0);
  const Camera& camera = *view.camera;
  const bool use_depth = options.occlusion.enabled && view.depth && !view.depth->empty();
  KernelContext k{
      .buffer = &buffer,
      .normals = triangle_normals.data(),
      .R = view.cam_from_local.RotationMatrix().cast<float>(),
      .t = view.cam_from_local.translation.cast<float>(),
      .centre = view.centre_local.cast<float>(),
      .projector = Projector(camera),
      .bounds = view.bounds.valid ? view.bounds : ComputeNormalizedBounds(camera),
      .near_m = static_cast<float>(options.near_m),
      .cos_max = static_cast<float>(std::cos(options.occlusion.max_view_angle_deg * M_PI / 180.0)),
      .max_u = static_cast<float>(camera.width - 1),
      .max_v = static_cast<float>(camera.height - 1),
      .focal = static_cast<float>(0.5 * (camera.fx + camera.fy)),
      .tol_rel = static_cast<float>(options.occlusion.tolerance_rel),
      .tol_abs = static_cast<float>(options.occlusion.tolerance_m),
      .slope_px = static_cast<float>(1.5 / (0.5 * (camera.fx + camera.fy))),
      .focal_texel = static_cast<float>(0.5 * (camera.fx + camera.fy) * buffer.texel_size_m),
      .frame = view.frame_bgr,
      .depth = use_depth ? view.depth : view.frame_bgr,
      .pyramid = &view.pyramid,
      .out_bgr = warped->bgr.data,
      .out_valid = warped->valid.data,
      .out_quality = warped->quality.ptr<float>()};
  const ChunkKernel kernel = SelectKernel(camera.HasDistortion(), use_depth, options.sampling);
  std::atomic<int> in_view{0}, visible{0}, occluded{0}, grazing{0}, culled{0};
  std::atomic<long long> tested{0};
  const int num_chunks = static_cast<int>(buffer.chunks.size());
  const double stripes = std::max(1, std::min(num_chunks, 16 * cv::getNumThreads()));
  cv::parallel_for_(
      cv::Range(0, num_chunks),
      [&](const cv::Range& range) {
        Counts n;
        for (int c = range.start; c < range.end; ++c) {
          const BaseBuffer::Chunk& chunk = buffer.chunks[c];
          if (ChunkCulled(k, chunk)) {
            ++n.culled;
            continue;
          }
          n.tested += chunk.end - chunk.begin;
          kernel(k, chunk, &n);
        }
        in_view += n.in_view, visible += n.visible, occluded += n.occluded;
        grazing += n.grazing, culled += n.culled, tested += n.tested;
      },
      stripes);
  warped->in_view = in_view;
  warped->visible = visible;
  warped->occluded = occluded;
  warped->grazing = grazing;
  warped->chunks_culled = culled;
  warped->texels_tested = tested;
}

}  // namespace fresco
