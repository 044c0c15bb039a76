#include "pipeline/paint/frame_warp.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>

#include <opencv2/core/utility.hpp>

namespace fresco {
namespace {

// A float copy of the camera for the hot loop (local coordinates keep values small, so
// float is ample: 1e-4 px at 1280 px). ProjectChunkBody applies Camera::Project's formulas.
struct Projector {
  float fx, fy, cx, cy, k1, k2, k3, k4, k5, k6, p1, p2, fold_r2;
  bool rational;  // k4..k6 not all 0
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
                                         : std::numeric_limits<float>::infinity()),
        rational(c.k4 != 0.0 || c.k5 != 0.0 || c.k6 != 0.0) {}
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
  PaintUpdateStats paint;  // when painting directly
};

// Everything the kernel needs, resolved once per buffer and frame.
struct KernelContext {
  const BaseBuffer* buffer;
  Eigen::Matrix3f R;
  Eigen::Vector3f t, centre;
  Projector projector;
  NormalizedBounds bounds;
  float near_m, cos_max, max_u, max_v, focal, tol_rel, tol_abs;
  float slope_px;     // 1.5 / focal: the occlusion tolerance's slope term per unit tan
  float focal_texel;  // focal * texel size: pixels per texel at z = 1 m, head-on
  const cv::Mat* frame;
  const cv::Mat* depth;
  const cv::Mat* depth_range;      // or null (FrameView::depth_range)
  int32_t frame_step, depth_step;  // bytes per row of each
  const std::vector<cv::Mat>* pyramid;
  uint8_t* out_bgr;
  uint8_t* out_valid;
  float* out_quality;
  // Painting directly (WarpAndPaintBuffer): the buffer's texels and the rule.
  uint8_t* paint_bgra = nullptr;
  float* paint_quality = nullptr;
  TexelUpdateRule rule;
  // ... and the sums of `update: mean` and `auto` (PaintedBuffer; null when not kept).
  float* mean_sum = nullptr;
  float* held_sum = nullptr;
  float* sharp_sum = nullptr;  // `auto` deciding: PaintedBuffer::sharp_sum, held_sharp_sum
  float* held_sharp_sum = nullptr;
  uint8_t* shadow_bgra = nullptr;
  float* shadow_quality = nullptr;
};

// One visible sample (BGR) into the painted texel `idx` by `k.rule`: what PaintBuffer paints
// for it without a mask or a background model (paint_update.cc's PaintTexel).
// `pixels_per_texel`: the view's (ChunkProjection::quality).
inline void PaintSample(const KernelContext& k, size_t idx, const uint8_t* sample,
                        float pixels_per_texel, bool on_surface, PaintUpdateStats* stats) {
  uint8_t* const texel = k.paint_bgra + 4 * idx;
  const float quality = std::min(1.0f, pixels_per_texel);
  if (k.mean_sum && !k.rule.mean_too) {
    MeanTexel(sample, k.rule.sharp ? SharpWeight(pixels_per_texel) : quality, quality,
              /*provisional=*/false, on_surface, texel, k.paint_quality + idx, k.mean_sum + 4 * idx,
              stats);
    return;
  }
  if (k.rule.mean_too) {  // `auto` deciding: the means beside the sharpest
    AddToMean(sample, quality, /*provisional=*/false, k.mean_sum + 4 * idx,
              k.held_sum ? k.held_sum + 4 * idx : nullptr, k.rule.held_out);
    if (k.sharp_sum)
      AddToMean(sample, SharpWeight(pixels_per_texel), /*provisional=*/false, k.sharp_sum + 4 * idx,
                k.held_sharp_sum + 4 * idx, k.rule.held_out);
    PaintUpdateStats ignored;
    if (!k.rule.held_out && k.shadow_bgra)
      UpdateTexel(k.rule, sample, quality, on_surface, k.shadow_bgra + 4 * idx,
                  k.shadow_quality + idx, &ignored);
  }
  UpdateTexel(k.rule, sample, quality, on_surface, texel, k.paint_quality + idx, stats);
}

// True when the box lies wholly behind the near plane or outside one side of the view
// frustum (all eight corners outside the same plane); R, t map the box's frame to the camera.
// Float for the chunks (per frame, many), double for whole buffers.
template <class T>
bool BoxOutsideView(const Eigen::Matrix<T, 3, 1>& lo, const Eigen::Matrix<T, 3, 1>& hi,
                    const Eigen::Matrix<T, 3, 3>& R, const Eigen::Matrix<T, 3, 1>& t,
                    const NormalizedBounds& bounds, T near_m) {
  int behind = 0, left = 0, right = 0, top = 0, bottom = 0;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Matrix<T, 3, 1> corner((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(),
                                        (c & 4) ? hi.z() : lo.z());
    const Eigen::Matrix<T, 3, 1> p = R * corner + t;
    behind += p.z() <= near_m;
    left += p.x() < bounds.x_min * p.z();
    right += p.x() > bounds.x_max * p.z();
    top += p.y() < bounds.y_min * p.z();
    bottom += p.y() > bounds.y_max * p.z();
  }
  if (behind == 8) return true;
  return bounds.valid && (left == 8 || right == 8 || top == 8 || bottom == 8);
}

bool ChunkOutsideView(const KernelContext& k, const BaseBuffer::Chunk& chunk) {
  return BoxOutsideView<float>(chunk.bounds_min, chunk.bounds_max, k.R, k.t, k.bounds, k.near_m);
}

// Pass 1, for a chunk of texels at once (SIMD: plain arithmetic over arrays, compiled for
// AVX2 and for the baseline, chosen at run time): transform, facing test, projection, image
// bounds, and the occlusion tolerance and quality of each texel. `code`: 0 skip (behind the
// camera, outside the image, beyond the lens's fold), 1 back-facing or grazing, 2 in view.
struct ChunkProjection {
  static constexpr int kMax = BaseBuffer::kTileTexels * BaseBuffer::kTileTexels;
  float u[kMax], v[kMax], z[kMax], tol[kMax], quality[kMax];
  // Bilinear footprint: top-left pixel (x0, y0), with x0 + 1 and y0 + 1 inside the image,
  // as byte offsets into the frame (y0 * step + 3 x0) and the depth map (y0 * step + 4 x0),
  // and the fractions towards the next pixel.
  int32_t frame_at[kMax], depth_at[kMax];
  float ax[kMax], ay[kMax];
  int32_t code[kMax];
};

// The lens terms the loop evaluates: none, the polynomial radial and tangential terms, or
// those and the rational denominator (k4..k6; most lenses have none: one division less).
enum class LensTerms { kNone, kPolynomial, kRational };

// Where pass 1 takes each texel's point and normal: the stored (quantized) arrays, or a
// full planar tile's plane and normal (BaseBuffer::Chunk::affine and uniform_normal).
enum class TileSource { kStored, kAffine };

template <LensTerms kLens, TileSource kTile>
__attribute__((always_inline)) inline void ProjectChunkBody(const KernelContext& k,
                                                            const BaseBuffer& buffer,
                                                            const BaseBuffer::Chunk& chunk,
                                                            ChunkProjection* out) {
  const int begin = chunk.begin, n = chunk.end - chunk.begin;
  const uint16_t* __restrict QX = buffer.point_qx.data() + begin;
  const uint16_t* __restrict QY = buffer.point_qy.data() + begin;
  const uint16_t* __restrict QZ = buffer.point_qz.data() + begin;
  const int16_t* __restrict QNX = buffer.normal_qx.data() + begin;
  const int16_t* __restrict QNY = buffer.normal_qy.data() + begin;
  const int16_t* __restrict QNZ = buffer.normal_qz.data() + begin;
  const float bx = chunk.bounds_min.x(), by = chunk.bounds_min.y(), bz = chunk.bounds_min.z();
  const float sx = chunk.point_step.x(), sy = chunk.point_step.y(), sz = chunk.point_step.z();
  constexpr float kInvNormal = 1.0f / BaseBuffer::kNormalScale;
  float* __restrict u = out->u;
  float* __restrict v = out->v;
  float* __restrict zo = out->z;
  float* __restrict tol = out->tol;
  float* __restrict quality = out->quality;
  int32_t* __restrict code = out->code;
  int32_t* __restrict frame_at = out->frame_at;
  int32_t* __restrict depth_at = out->depth_at;
  const int32_t frame_step = k.frame_step, depth_step = k.depth_step;
  float* __restrict ax = out->ax;
  float* __restrict ay = out->ay;

  const float r00 = k.R(0, 0), r01 = k.R(0, 1), r02 = k.R(0, 2);
  const float r10 = k.R(1, 0), r11 = k.R(1, 1), r12 = k.R(1, 2);
  const float r20 = k.R(2, 0), r21 = k.R(2, 1), r22 = k.R(2, 2);
  const float tx = k.t.x(), ty = k.t.y(), tz = k.t.z();
  const float ox = k.centre.x(), oy = k.centre.y(), oz = k.centre.z();
  const float cos2_max = k.cos_max > 0.0f ? k.cos_max * k.cos_max : 0.0f;
  const Projector& pr = k.projector;
  const float fx = pr.fx, fy = pr.fy, cx = pr.cx, cy = pr.cy;
  const float k1 = pr.k1, k2 = pr.k2, k3 = pr.k3, k4 = pr.k4, k5 = pr.k5, k6 = pr.k6;
  const float p1 = pr.p1, p2 = pr.p2, fold_r2 = pr.fold_r2;
  const float near_m = k.near_m, max_u = k.max_u, max_v = k.max_v;
  // The last position whose bilinear neighbours are all inside (a 1/1024 px clamp at the
  // right and bottom edges).
  const float max_u_in = std::max(0.0f, max_u - 1.0f / 1024);
  const float max_v_in = std::max(0.0f, max_v - 1.0f / 1024);
  const float tol_rel = k.tol_rel, tol_abs = k.tol_abs, slope_px = k.slope_px;
  constexpr float kEdgeSlackPx = 1.0f / 256;
  const float focal_texel = k.focal_texel;
  const auto project = [&](int i, float X, float Y, float Z, float NX, float NY, float NZ)
      __attribute__((always_inline)) {
    const float px = r00 * X + r01 * Y + r02 * Z + tx;
    const float py = r10 * X + r11 * Y + r12 * Z + ty;
    const float pz = r20 * X + r21 * Y + r22 * Z + tz;
    const float dx = ox - X, dy = oy - Y, dz = oz - Z;
    const float nd = NX * dx + NY * dy + NZ * dz;
    const float dd = dx * dx + dy * dy + dz * dz;
    // Branch-free (bitwise & on 0/1 ints, selects on floats) so that the loop vectorizes.
    const int front = pz > near_m;
    const int facing = (nd > 0.0f) & (nd * nd >= cos2_max * dd);
    const float z_safe = std::max(pz, near_m);
    const float inv_z = 1.0f / z_safe;
    const float x = px * inv_z, y = py * inv_z;
    float uu, vv;
    int inside_fold = 1;
    if constexpr (kLens == LensTerms::kNone) {
      uu = fx * x + cx;
      vv = fy * y + cy;
    } else {
      const float r2 = x * x + y * y;
      const float num = 1.0f + r2 * (k1 + r2 * (k2 + r2 * k3));
      float f = num;
      if constexpr (kLens == LensTerms::kRational) f /= 1.0f + r2 * (k4 + r2 * (k5 + r2 * k6));
      const float two_xy = 2.0f * x * y;
      uu = fx * (x * f + p1 * two_xy + p2 * (r2 + 2.0f * x * x)) + cx;
      vv = fy * (y * f + p1 * (r2 + 2.0f * y * y) + p2 * two_xy) + cy;
      inside_fold = r2 <= fold_r2;
    }
    // A texel centre projecting onto the border pixels' centres (a texel per pixel facing
    // the camera) must not drop out for a rounding error: 1/256 px of slack, clamped back.
    const int in_image = (uu >= -kEdgeSlackPx) & (vv >= -kEdgeSlackPx) &
                         (uu <= max_u + kEdgeSlackPx) & (vv <= max_v + kEdgeSlackPx) & inside_fold;
    const int c = front * (1 - facing + 2 * facing * in_image);
    code[i] = c;
    u[i] = c == 2 ? std::min(std::max(uu, 0.0f), max_u) : 0.0f;  // inside the image wherever
    v[i] = c == 2 ? std::min(std::max(vv, 0.0f), max_v) : 0.0f;  // pass 2 looks
    const float uc = std::min(std::max(u[i], 0.0f), max_u_in);
    const float vc = std::min(std::max(v[i], 0.0f), max_v_in);
    const int xi = static_cast<int>(uc), yi = static_cast<int>(vc);
    frame_at[i] = yi * frame_step + 3 * xi;
    depth_at[i] = yi * depth_step + 4 * xi;
    ax[i] = uc - static_cast<float>(xi);
    ay[i] = vc - static_cast<float>(yi);
    zo[i] = pz;
    // Occlusion tolerance: relative + absolute, plus the depth change across 1.5 pixels at
    // this slope (tan of the view angle = |n x d| / n.d).
    const float nd_safe = std::max(nd, 1e-12f);
    const float tan_view = std::sqrt(std::max(0.0f, dd - nd * nd)) / nd_safe;
    tol[i] = pz * (tol_rel + slope_px * tan_view) + tol_abs;
    // Pixels per texel: f s cos(view) / z (the rules count it up to 1: RuleQuality).
    quality[i] = focal_texel * nd_safe / (std::sqrt(dd) * z_safe);
  };
  if constexpr (kTile == TileSource::kAffine) {
    // Points from the tile's plane, the normal the tile's own (BaseBuffer::Chunk::affine:
    // full tiles of kTileTexels columns, so texel i sits at column i % 16, row i / 16).
    static_assert(BaseBuffer::kTileTexels == 16);
    const float NX = chunk.normal.x(), NY = chunk.normal.y(), NZ = chunk.normal.z();
    const float ax0 = chunk.affine_origin.x(), ay0 = chunk.affine_origin.y(),
                az0 = chunk.affine_origin.z();
    const float dux = chunk.affine_du.x(), duy = chunk.affine_du.y(), duz = chunk.affine_du.z();
    const float dvx = chunk.affine_dv.x(), dvy = chunk.affine_dv.y(), dvz = chunk.affine_dv.z();
    alignas(32) float PX[ChunkProjection::kMax], PY[ChunkProjection::kMax],
        PZ[ChunkProjection::kMax];
    for (int i = 0; i < n; ++i) {
      const float c = static_cast<float>(i & 15), r = static_cast<float>(i >> 4);
      PX[i] = ax0 + c * dux + r * dvx;
      PY[i] = ay0 + c * duy + r * dvy;
      PZ[i] = az0 + c * duz + r * dvz;
    }
    for (int i = 0; i < n; ++i) project(i, PX[i], PY[i], PZ[i], NX, NY, NZ);
  } else {
    for (int i = 0; i < n; ++i) {
      project(i, bx + static_cast<float>(QX[i]) * sx, by + static_cast<float>(QY[i]) * sy,
              bz + static_cast<float>(QZ[i]) * sz, static_cast<float>(QNX[i]) * kInvNormal,
              static_cast<float>(QNY[i]) * kInvNormal, static_cast<float>(QNZ[i]) * kInvNormal);
    }
  }
}

__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) void ProjectChunkPinhole(
    const KernelContext& k, const BaseBuffer& buffer, const BaseBuffer::Chunk& chunk,
    ChunkProjection* out) {
  if (chunk.affine && chunk.uniform_normal)
    ProjectChunkBody<LensTerms::kNone, TileSource::kAffine>(k, buffer, chunk, out);
  else
    ProjectChunkBody<LensTerms::kNone, TileSource::kStored>(k, buffer, chunk, out);
}

__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) void ProjectChunkDistorted(
    const KernelContext& k, const BaseBuffer& buffer, const BaseBuffer::Chunk& chunk,
    ChunkProjection* out) {
  const bool affine = chunk.affine && chunk.uniform_normal;
  if (k.projector.rational) {
    if (affine)
      ProjectChunkBody<LensTerms::kRational, TileSource::kAffine>(k, buffer, chunk, out);
    else
      ProjectChunkBody<LensTerms::kRational, TileSource::kStored>(k, buffer, chunk, out);
  } else if (affine) {
    ProjectChunkBody<LensTerms::kPolynomial, TileSource::kAffine>(k, buffer, chunk, out);
  } else {
    ProjectChunkBody<LensTerms::kPolynomial, TileSource::kStored>(k, buffer, chunk, out);
  }
}

// Pass 2 for the common case (bilinear samples painted directly, a new sample replacing the
// stored one), in three steps so that the arithmetic vectorizes: gather what each texel in
// view reads (its four depths, its four pixels, the stored texel and quality; scalar loads,
// which are faster than vector gathers), then the depth test, the bilinear blend and the
// update rule over the gathered arrays (SIMD), then the stores. The figures and the texels
// written are bit for bit those of the per-texel loop (the same float operations in the same
// order; paint_in_warp_test checks it).
struct PaintBatch {
  static constexpr int kMax = ChunkProjection::kMax;
  float d00[kMax], d10[kMax], d01[kMax], d11[kMax];  // depths around the sample
  float range[2 * kMax];  // or their least and greatest (FrameView::depth_range)
  uint32_t p00[kMax], p10[kMax], p01[kMax], p11[kMax];  // the four pixels' BGR (low 24 bits)
  uint32_t stored[kMax];                                // the stored BGRA
  float stored_q[kMax];
  uint32_t out[kMax];  // what the stored texel and quality become
  float out_q[kMax];
  int32_t write[kMax];
};

struct PaintBatchSums {
  int visible = 0, compared = 0, rejected = 0, written = 0, newly_painted = 0;
  int abs_grey_difference_sum = 0;  // at most 256 texels x 255
};

inline uint32_t Load32(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

// Texel j of a batch: whether it is in view and passes the occlusion test. kDepth: 0 no
// occlusion test, 1 the four depths, 2 their range.
template <int kDepth>
__attribute__((always_inline)) inline int BatchVisible(int j,
                                                       const ChunkProjection* __restrict proj,
                                                       const PaintBatch* __restrict b) {
  int ok = proj->code[j] == 2;  // in view (the others read pixel (0, 0) and are left alone)
  if constexpr (kDepth == 1) {
    const float zz = proj->z[j], t = proj->tol[j];
    ok &= (std::abs(b->d00[j] - zz) <= t) & (std::abs(b->d10[j] - zz) <= t) &
          (std::abs(b->d01[j] - zz) <= t) & (std::abs(b->d11[j] - zz) <= t);
  } else if constexpr (kDepth == 2) {
    // |d - z| <= t for all four <=> max - z <= t and z - min <= t (rounding is monotonic;
    // an infinite depth fails both ways).
    const float zz = proj->z[j], t = proj->tol[j];
    ok &= (b->range[2 * j + 1] - zz <= t) & (zz - b->range[2 * j] <= t);
  }
  return ok;
}

// Texel j's bilinear sample, BGR in the low 24 bits (alpha 255), and its channels.
__attribute__((always_inline)) inline uint32_t BatchBilinear(int j,
                                                             const ChunkProjection* __restrict proj,
                                                             const PaintBatch* __restrict b,
                                                             int channel[3]) {
  const float fx = proj->ax[j], fy = proj->ay[j];
  const float w00 = (1 - fx) * (1 - fy), w10 = fx * (1 - fy), w01 = (1 - fx) * fy, w11 = fx * fy;
  uint32_t sample = 0xFF000000u;
  for (int c = 0; c < 3; ++c) {
    const int shift = 8 * c;
    const float s = w00 * static_cast<float>(static_cast<int>((b->p00[j] >> shift) & 255u)) +
                    w10 * static_cast<float>(static_cast<int>((b->p10[j] >> shift) & 255u)) +
                    w01 * static_cast<float>(static_cast<int>((b->p01[j] >> shift) & 255u)) +
                    w11 * static_cast<float>(static_cast<int>((b->p11[j] >> shift) & 255u)) + 0.5f;
    channel[c] = static_cast<int>(s);
    sample |= static_cast<uint32_t>(channel[c]) << shift;
  }
  return sample;
}

template <int kDepth>
__attribute__((always_inline)) inline PaintBatchSums PaintBatchBody(
    int n, bool quality_policy, float keep, const ChunkProjection* __restrict proj,
    const uint8_t* __restrict on_surface, PaintBatch* __restrict b) {
  const uint32_t* __restrict stored = b->stored;
  const float* __restrict stored_q = b->stored_q;
  const float* __restrict quality = proj->quality;
  uint32_t* __restrict out = b->out;
  float* __restrict out_q = b->out_q;
  int32_t* __restrict write_out = b->write;
  const int by_quality = quality_policy;
  int visible = 0, compared = 0, rejected = 0, written = 0, newly = 0, diff_sum = 0;
  for (int j = 0; j < n; ++j) {
    const int ok = BatchVisible<kDepth>(j, proj, b);
    int channel[3];
    const uint32_t sample = BatchBilinear(j, proj, b, channel);
    const uint32_t old = stored[j];
    const int has = (old >> 24) != 0;
    const int new_grey = (29 * channel[0] + 150 * channel[1] + 77 * channel[2]) >> 8;
    const int old_grey =
        (29 * static_cast<int>(old & 255u) + 150 * static_cast<int>((old >> 8) & 255u) +
         77 * static_cast<int>((old >> 16) & 255u)) >>
        8;
    const int d = new_grey - old_grey;
    const int compare = ok & has;
    diff_sum += compare * (d < 0 ? -d : d);
    compared += compare;
    const float q = std::min(1.0f, quality[j]), sq = stored_q[j];
    const int reject = ok & by_quality & (q < sq * keep);
    const int write = ok & (1 - reject);
    visible += ok;
    rejected += reject;
    written += write;
    newly += write & (1 - has) & static_cast<int>(on_surface[j] != 0);
    out[j] = write ? sample : old;
    out_q[j] = write ? (by_quality ? std::max(sq, q) : q) : sq;
    write_out[j] = write;
  }
  PaintBatchSums sums;
  sums.visible = visible, sums.compared = compared, sums.rejected = rejected;
  sums.written = written, sums.newly_painted = newly, sums.abs_grey_difference_sum = diff_sum;
  return sums;
}

// The samples alone (the warped buffer that later stages read): b->out[j] the sample, b->write[j]
// whether texel j is visible. Returns how many are.
template <int kDepth>
__attribute__((always_inline)) inline int SampleBatchBody(int n,
                                                          const ChunkProjection* __restrict proj,
                                                          PaintBatch* __restrict b) {
  int visible = 0;
  for (int j = 0; j < n; ++j) {
    const int ok = BatchVisible<kDepth>(j, proj, b);
    int channel[3];
    b->out[j] = BatchBilinear(j, proj, b, channel);
    b->write[j] = ok;
    visible += ok;
  }
  return visible;
}

__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) int SampleBatchDepth(
    int n, const ChunkProjection* proj, PaintBatch* b) {
  return SampleBatchBody<1>(n, proj, b);
}

__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) int SampleBatchDepthRange(
    int n, const ChunkProjection* proj, PaintBatch* b) {
  return SampleBatchBody<2>(n, proj, b);
}

__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) int SampleBatchNoDepth(
    int n, const ChunkProjection* proj, PaintBatch* b) {
  return SampleBatchBody<0>(n, proj, b);
}

__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) PaintBatchSums PaintBatchDepth(
    int n, bool quality_policy, float keep, const ChunkProjection* proj, const uint8_t* on_surface,
    PaintBatch* b) {
  return PaintBatchBody<1>(n, quality_policy, keep, proj, on_surface, b);
}

__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) PaintBatchSums
PaintBatchDepthRange(int n, bool quality_policy, float keep, const ChunkProjection* proj,
                     const uint8_t* on_surface, PaintBatch* b) {
  return PaintBatchBody<2>(n, quality_policy, keep, proj, on_surface, b);
}

__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) PaintBatchSums
PaintBatchNoDepth(int n, bool quality_policy, float keep, const ChunkProjection* proj,
                  const uint8_t* on_surface, PaintBatch* b) {
  return PaintBatchBody<0>(n, quality_policy, keep, proj, on_surface, b);
}

// How many texels of a projected chunk are in view (code 2) and how many grazing (code 1).
void CountCodes(const ChunkProjection& proj, int n, int* in_view, int* grazing) {
  int view = 0, graze = 0;
  for (int i = 0; i < n; ++i) {
    view += proj.code[i] == 2;
    graze += proj.code[i] == 1;
  }
  *in_view = view, *grazing = graze;
}

// A full tile's rows between the buffer (texels and qualities, rows `buffer_w` long) and a
// batch's arrays (the tile's texels row by row). Full-width tiles copy rows of a constant
// size: a few vector moves each.
template <bool kToBuffer>
void CopyTileRows(const BaseBuffer::Chunk& chunk, int buffer_w, uint8_t* bgra, float* quality,
                  uint32_t* texels, float* qualities) {
  const auto copy = [&](auto width) {
    for (int r = 0, i = 0; r < chunk.y1 - chunk.y0; ++r, i += width) {
      const size_t idx = static_cast<size_t>(chunk.y0 + r) * buffer_w + chunk.x0;
      if constexpr (kToBuffer) {
        std::memcpy(bgra + 4 * idx, texels + i, 4 * width);
        std::memcpy(quality + idx, qualities + i, sizeof(float) * width);
      } else {
        std::memcpy(texels + i, bgra + 4 * idx, 4 * width);
        std::memcpy(qualities + i, quality + idx, sizeof(float) * width);
      }
    }
  };
  if (chunk.x1 - chunk.x0 == BaseBuffer::kTileTexels)
    copy(std::integral_constant<int, BaseBuffer::kTileTexels>());
  else
    copy(chunk.x1 - chunk.x0);
}

// What every texel of a projected chunk reads: the occlusion test's depths (one pair of the
// range map, 8 bytes per pixel at twice the depth map's offset, or the four depths) and the
// four pixels around its sample.
template <bool kDepth>
void GatherBatch(const KernelContext& k, const ChunkProjection& proj, int n, PaintBatch* b) {
  const uint8_t* const frame = k.frame->data;
  const size_t frame_step = k.frame->step[0];
  const uint8_t* const depth = k.depth->data;
  const size_t depth_step = k.depth->step[0];
  const uint8_t* const range = k.depth_range ? k.depth_range->data : nullptr;
  for (int i = 0; i < n; ++i) {
    if (kDepth && range) {
      std::memcpy(&b->range[2 * i], range + 2 * static_cast<size_t>(proj.depth_at[i]), 8);
    } else if constexpr (kDepth) {
      const float* d0 = reinterpret_cast<const float*>(depth + proj.depth_at[i]);
      const float* d1 =
          reinterpret_cast<const float*>(reinterpret_cast<const uint8_t*>(d0) + depth_step);
      b->d00[i] = d0[0], b->d10[i] = d0[1], b->d01[i] = d1[0], b->d11[i] = d1[1];
    }
    // Pixel x0's BGR and the next one's (read from its red byte on: no byte past the pair).
    const uint8_t* r0 = frame + proj.frame_at[i];
    const uint8_t* r1 = r0 + frame_step;
    b->p00[i] = Load32(r0);
    b->p10[i] = Load32(r0 + 2) >> 8;
    b->p01[i] = Load32(r1);
    b->p11[i] = Load32(r1 + 2) >> 8;
  }
}

// Gathers what every texel of a projected chunk reads, runs the batch, stores what it wrote.
// Texels out of view (`in_view` of the chunk's `n` are in view) are masked in the batch.
template <bool kDepth>
void PaintChunkBatched(const KernelContext& k, const BaseBuffer::Chunk& chunk,
                       const ChunkProjection& proj, int in_view, int grazing, Counts* counts) {
  PaintBatch batch;
  const int n = chunk.end - chunk.begin;
  const int32_t* const texel_index = k.buffer->texel_index.data() + chunk.begin;
  const uint8_t* const on_surface = k.buffer->on_surface.data() + chunk.begin;
  const uint8_t* const bgra = k.paint_bgra;
  const float* const stored_quality = k.paint_quality;
  // A full tile's rows are runs of the buffer's rows: its stored texels are read and written
  // a row at a time. Otherwise texel by texel through texel_index.
  if (chunk.full) {
    CopyTileRows</*kToBuffer=*/false>(chunk, k.buffer->width, k.paint_bgra, k.paint_quality,
                                      batch.stored, batch.stored_q);
  } else {
    for (int i = 0; i < n; ++i) {
      const size_t idx = static_cast<size_t>(texel_index[i]);
      batch.stored[i] = Load32(bgra + 4 * idx);
      batch.stored_q[i] = stored_quality[idx];
    }
  }
  GatherBatch<kDepth>(k, proj, n, &batch);
  const bool by_quality = k.rule.policy == UpdatePolicy::kQuality;
  const PaintBatchSums sums =
      !kDepth         ? PaintBatchNoDepth(n, by_quality, k.rule.keep, &proj, on_surface, &batch)
      : k.depth_range ? PaintBatchDepthRange(n, by_quality, k.rule.keep, &proj, on_surface, &batch)
                      : PaintBatchDepth(n, by_quality, k.rule.keep, &proj, on_surface, &batch);
  uint8_t* const out_bgra = k.paint_bgra;
  float* const out_quality = k.paint_quality;
  if (chunk.full) {
    // Unwritten texels keep what they held (out and out_q are the stored values there), so
    // whole rows are written back; no other thread touches this tile.
    CopyTileRows</*kToBuffer=*/true>(chunk, k.buffer->width, out_bgra, out_quality, batch.out,
                                     batch.out_q);
  } else {
    for (int i = 0; i < n; ++i) {
      if (!batch.write[i]) continue;
      const size_t idx = static_cast<size_t>(texel_index[i]);
      std::memcpy(out_bgra + 4 * idx, &batch.out[i], 4);
      out_quality[idx] = batch.out_q[i];
    }
  }
  counts->in_view += in_view, counts->visible += sums.visible;
  counts->occluded += in_view - sums.visible, counts->grazing += grazing;
  PaintUpdateStats stats;
  stats.written = sums.written, stats.rejected = sums.rejected, stats.compared = sums.compared;
  stats.abs_grey_difference_sum = sums.abs_grey_difference_sum;
  stats.newly_painted = sums.newly_painted;
  counts->paint.Add(stats);
}

// The batch's depth test and bilinear sample (b->out, b->write: SampleBatchBody); returns how
// many texels are visible.
template <bool kDepth>
int SampleChunk(const KernelContext& k, const ChunkProjection& proj, int n, PaintBatch* b) {
  GatherBatch<kDepth>(k, proj, n, b);
  return !kDepth         ? SampleBatchNoDepth(n, &proj, b)
         : k.depth_range ? SampleBatchDepthRange(n, &proj, b)
                         : SampleBatchDepth(n, &proj, b);
}

// Painting with the sums of `update: mean` or `auto` (KernelContext::mean_sum): the batch's
// depth test and bilinear sample, then each visible texel painted (PaintSample).
template <bool kDepth>
void PaintSumsChunkBatched(const KernelContext& k, const BaseBuffer::Chunk& chunk,
                           const ChunkProjection& proj, int in_view, int grazing, Counts* counts) {
  PaintBatch batch;
  const int n = chunk.end - chunk.begin;
  const int visible = SampleChunk<kDepth>(k, proj, n, &batch);
  const int32_t* const texel_index = k.buffer->texel_index.data() + chunk.begin;
  const uint8_t* const on_surface = k.buffer->on_surface.data() + chunk.begin;
  PaintUpdateStats stats;
  for (int i = 0; i < n; ++i) {
    if (!batch.write[i]) continue;
    const uint32_t bgr = batch.out[i];
    const uint8_t sample[3] = {static_cast<uint8_t>(bgr), static_cast<uint8_t>(bgr >> 8),
                               static_cast<uint8_t>(bgr >> 16)};
    PaintSample(k, static_cast<size_t>(texel_index[i]), sample, proj.quality[i], on_surface[i] != 0,
                &stats);
  }
  counts->in_view += in_view, counts->visible += visible;
  counts->occluded += in_view - visible, counts->grazing += grazing;
  counts->paint.Add(stats);
}

// Pass 2 when later stages read the warped samples (no painting here): the batch's depth
// test and bilinear sample, then each visible texel's sample, quality and valid flag stored.
// The same samples, to the bit, as the texel-by-texel loop.
template <bool kDepth>
void SampleChunkBatched(const KernelContext& k, const BaseBuffer::Chunk& chunk,
                        const ChunkProjection& proj, int in_view, int grazing, Counts* counts) {
  PaintBatch batch;
  const int n = chunk.end - chunk.begin;
  const int visible = SampleChunk<kDepth>(k, proj, n, &batch);
  const int32_t* const texel_index = k.buffer->texel_index.data() + chunk.begin;
  for (int i = 0; i < n; ++i) {
    if (!batch.write[i]) continue;
    const size_t idx = static_cast<size_t>(texel_index[i]);
    uint8_t* out = k.out_bgr + 3 * idx;
    const uint32_t sample = batch.out[i];
    out[0] = static_cast<uint8_t>(sample), out[1] = static_cast<uint8_t>(sample >> 8);
    out[2] = static_cast<uint8_t>(sample >> 16);
    k.out_valid[idx] = 255;
    k.out_quality[idx] = proj.quality[i];
  }
  counts->in_view += in_view, counts->visible += visible;
  counts->occluded += in_view - visible, counts->grazing += grazing;
}

// Pass 2, texel by texel for those in view: the depth test and the sample. Works on local
// copies of what it reads: its outputs are written through byte pointers, which may alias
// anything, so fields read through references would be reloaded for every texel.
template <bool kDistorted, SamplingMode kMode, bool kDepth, bool kPaint>
void WarpChunk(const KernelContext& context, const BaseBuffer::Chunk& chunk, Counts* counts) {
  const KernelContext k = context;
  // The tile's rows of what pass 2 writes (16 rows, a cache line or two each): fetched while
  // pass 1 projects, they are in cache when the scattered-by-row writes come.
  const size_t width = static_cast<size_t>(k.buffer->width);
  const size_t last = static_cast<size_t>(chunk.x1 - chunk.x0 - 1);  // a row may span 2 lines
  for (int y = chunk.y0; y < chunk.y1; ++y) {
    const size_t row = static_cast<size_t>(y) * width + static_cast<size_t>(chunk.x0);
    if constexpr (kPaint) {
      __builtin_prefetch(k.paint_bgra + 4 * row, 1);
      __builtin_prefetch(k.paint_bgra + 4 * (row + last) + 3, 1);
      __builtin_prefetch(k.paint_quality + row, 1);
      __builtin_prefetch(k.paint_quality + row + last, 1);
    } else {
      __builtin_prefetch(k.out_bgr + 3 * row, 1);
      __builtin_prefetch(k.out_bgr + 3 * (row + last) + 2, 1);
      __builtin_prefetch(k.out_valid + row, 1);
      __builtin_prefetch(k.out_quality + row, 1);
      __builtin_prefetch(k.out_quality + row + last, 1);
    }
  }
  ChunkProjection proj;
  const int n = chunk.end - chunk.begin;
  if constexpr (kDistorted)
    ProjectChunkDistorted(k, *k.buffer, chunk, &proj);
  else
    ProjectChunkPinhole(k, *k.buffer, chunk, &proj);

  if constexpr (kPaint && kMode == SamplingMode::kBilinear) {
    // The whole chunk as a batch, texels out of view masked (a chunk with none in view
    // is only counted).
    if (k.mean_sum) {
      int in_view, grazing;
      CountCodes(proj, n, &in_view, &grazing);
      if (in_view == 0) {
        counts->grazing += grazing;
        return;
      }
      return PaintSumsChunkBatched<kDepth>(k, chunk, proj, in_view, grazing, counts);
    }
    if (k.rule.weight == 256) {
      int in_view, grazing;
      CountCodes(proj, n, &in_view, &grazing);
      if (in_view == 0) {
        counts->grazing += grazing;
        return;
      }
      return PaintChunkBatched<kDepth>(k, chunk, proj, in_view, grazing, counts);
    }
  }
  if constexpr (!kPaint && kMode == SamplingMode::kBilinear) {
    int in_view, grazing;
    CountCodes(proj, n, &in_view, &grazing);
    if (in_view == 0) {
      counts->grazing += grazing;
      return;
    }
    return SampleChunkBatched<kDepth>(k, chunk, proj, in_view, grazing, counts);
  }
  const int32_t* const texel_index = k.buffer->texel_index.data() + chunk.begin;
  const uint8_t* const on_surface = k.buffer->on_surface.data() + chunk.begin;
  const float texel_size_m = static_cast<float>(k.buffer->texel_size_m);
  const uint8_t* const frame = k.frame->data;
  const size_t frame_step = k.frame->step[0];
  const int levels = static_cast<int>(k.pyramid->size());
  const uint8_t* const depth = k.depth->data;
  const size_t depth_step = k.depth->step[0];
  auto depth_at = [&](int x, int y) {
    return reinterpret_cast<const float*>(depth + y * depth_step)[x];
  };
  int in_view = 0, visible = 0, occluded = 0, grazing = 0;
  // A local (the counts behind a pointer could alias the byte writes: every texel would
  // reload and store the sums).
  PaintUpdateStats paint_stats;
  for (int i = 0; i < n; ++i) {
    const int code = proj.code[i];
    if (code != 2) {
      grazing += code == 1;
      continue;
    }
    ++in_view;
    const float u = proj.u[i], v = proj.v[i], z = proj.z[i];
    if constexpr (kDepth) {
      // Scalar: gathers are slow on some CPUs (measured slower here).
      const float tol = proj.tol[i];
      bool ok;
      if constexpr (kMode == SamplingMode::kNearest) {
        ok = std::abs(depth_at(static_cast<int>(u + 0.5f), static_cast<int>(v + 0.5f)) - z) <= tol;
      } else {
        const float* d0 = reinterpret_cast<const float*>(depth + proj.depth_at[i]);
        const float* d1 =
            reinterpret_cast<const float*>(reinterpret_cast<const uint8_t*>(d0) + depth_step);
        ok = std::abs(d0[0] - z) <= tol && std::abs(d0[1] - z) <= tol &&
             std::abs(d1[0] - z) <= tol && std::abs(d1[1] - z) <= tol;
      }
      if (!ok) {
        ++occluded;
        continue;
      }
    }
    ++visible;
    const int idx = texel_index[i];
    uint8_t sample[3];
    if constexpr (kMode == SamplingMode::kNearest) {
      const uint8_t* src =
          frame + static_cast<int>(v + 0.5f) * frame_step + 3 * static_cast<int>(u + 0.5f);
      sample[0] = src[0], sample[1] = src[1], sample[2] = src[2];
    } else if constexpr (kMode == SamplingMode::kBilinear) {
      const uint8_t* r0 = frame + proj.frame_at[i];
      const uint8_t* r1 = r0 + frame_step;
      const float fx = proj.ax[i], fy = proj.ay[i];
      const float w00 = (1 - fx) * (1 - fy), w10 = fx * (1 - fy), w01 = (1 - fx) * fy,
                  w11 = fx * fy;
      for (int c = 0; c < 3; ++c)
        sample[c] = static_cast<uint8_t>(w00 * r0[c] + w10 * r0[3 + c] + w01 * r1[c] +
                                         w11 * r1[3 + c] + 0.5f);
    } else {
      // Area: bilinear on the pyramid level whose pixels match the texel's footprint.
      const float footprint = k.focal * texel_size_m / z;
      const int level = std::clamp(
          static_cast<int>(std::floor(std::log2(std::max(footprint, 1.0f)))), 0, levels - 1);
      const float scale = 1.0f / static_cast<float>(1 << level);
      SampleBilinear(levels > 0 ? (*k.pyramid)[level] : *k.frame, (u + 0.5f) * scale - 0.5f,
                     (v + 0.5f) * scale - 0.5f, sample);
    }
    if constexpr (kPaint) {
      PaintSample(k, static_cast<size_t>(idx), sample, proj.quality[i], on_surface[i] != 0,
                  &paint_stats);
    } else {
      uint8_t* out = k.out_bgr + 3 * static_cast<size_t>(idx);
      out[0] = sample[0], out[1] = sample[1], out[2] = sample[2];
      k.out_valid[idx] = 255;
      k.out_quality[idx] = proj.quality[i];
    }
  }
  counts->in_view += in_view, counts->visible += visible;
  counts->occluded += occluded, counts->grazing += grazing;
  if constexpr (kPaint) counts->paint.Add(paint_stats);
}

using ChunkKernel = void (*)(const KernelContext&, const BaseBuffer::Chunk&, Counts*);

template <bool kDistorted, bool kDepth, bool kPaint>
ChunkKernel SelectForMode(SamplingMode mode) {
  switch (mode) {
    case SamplingMode::kNearest:
      return &WarpChunk<kDistorted, SamplingMode::kNearest, kDepth, kPaint>;
    case SamplingMode::kArea:
      return &WarpChunk<kDistorted, SamplingMode::kArea, kDepth, kPaint>;
    default:
      return &WarpChunk<kDistorted, SamplingMode::kBilinear, kDepth, kPaint>;
  }
}

template <bool kPaint>
ChunkKernel SelectKernel(bool distorted, bool depth, SamplingMode mode) {
  if (distorted)
    return depth ? SelectForMode<true, true, kPaint>(mode)
                 : SelectForMode<true, false, kPaint>(mode);
  return depth ? SelectForMode<false, true, kPaint>(mode)
               : SelectForMode<false, false, kPaint>(mode);
}

}  // namespace

NormalizedBounds ComputeNormalizedBounds(const Camera& camera) {
  // The image border unprojected: its corners for a pinhole (straight edges), 256 samples per
  // side for a lens with distortion (a few pixels apart: between them a smooth lens's border
  // bulges by far less than the margin below).
  const int steps = camera.HasDistortion() ? 256 : 1;
  NormalizedBounds b;
  b.x_min = b.y_min = std::numeric_limits<float>::max();
  b.x_max = b.y_max = -std::numeric_limits<float>::max();
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
  // A margin of 1 % and two pixels: rounding, the texels' 1/256 px edge slack, the bulge.
  const float mx = 0.01f * (b.x_max - b.x_min) + static_cast<float>(2.0 / camera.fx);
  const float my = 0.01f * (b.y_max - b.y_min) + static_cast<float>(2.0 / camera.fy);
  b.x_min -= mx, b.x_max += mx, b.y_min -= my, b.y_max += my;
  b.valid = true;
  return b;
}

namespace {

__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) void DepthRangeRow(
    const float* __restrict d0, const float* __restrict d1, int w, float* __restrict out) {
  for (int x = 0; x + 1 < w; ++x) {
    const float lo0 = std::min(d0[x], d0[x + 1]), lo1 = std::min(d1[x], d1[x + 1]);
    const float hi0 = std::max(d0[x], d0[x + 1]), hi1 = std::max(d1[x], d1[x + 1]);
    out[2 * x] = std::min(lo0, lo1);
    out[2 * x + 1] = std::max(hi0, hi1);
  }
  if (w > 0) {
    out[2 * (w - 1)] = std::min(d0[w - 1], d1[w - 1]);
    out[2 * (w - 1) + 1] = std::max(d0[w - 1], d1[w - 1]);
  }
}

}  // namespace

void DepthRange2x2(const cv::Mat& depth, cv::Mat* range, int row0, int row1) {
  const int w = depth.cols, h = depth.rows;
  range->create(h, w, CV_32FC2);
  row0 = std::clamp(row0, 0, h), row1 = row1 < 0 ? h : std::clamp(row1, row0, h);
  cv::parallel_for_(cv::Range(row0, row1), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y)
      DepthRangeRow(depth.ptr<float>(y), depth.ptr<float>(std::min(y + 1, h - 1)), w,
                    range->ptr<float>(y));
  });
}

bool BoundsOutsideView(const Eigen::Vector3d& bounds_min, const Eigen::Vector3d& bounds_max,
                       const FrameView& view, double near_m) {
  return BoxOutsideView<double>(bounds_min, bounds_max, view.cam_from_local.RotationMatrix(),
                                view.cam_from_local.translation, view.bounds, near_m);
}

namespace {

// The kernel's context for one buffer and frame; outputs left null.
KernelContext MakeContext(const BaseBuffer& buffer, const FrameView& view,
                          const WarpOptions& options, bool use_depth) {
  const Camera& camera = *view.camera;
  const double focal = 0.5 * (camera.fx + camera.fy);
  return KernelContext{
      .buffer = &buffer,
      .R = view.cam_from_local.RotationMatrix().cast<float>(),
      .t = view.cam_from_local.translation.cast<float>(),
      .centre = view.centre_local.cast<float>(),
      .projector = Projector(camera),
      .bounds = view.bounds.valid ? view.bounds : ComputeNormalizedBounds(camera),
      .near_m = static_cast<float>(options.near_m),
      .cos_max = static_cast<float>(std::cos(options.occlusion.max_view_angle_deg * M_PI / 180.0)),
      .max_u = static_cast<float>(camera.width - 1),
      .max_v = static_cast<float>(camera.height - 1),
      .focal = static_cast<float>(focal),
      .tol_rel = static_cast<float>(options.occlusion.tolerance_rel),
      .tol_abs = static_cast<float>(options.occlusion.tolerance_m),
      .slope_px = static_cast<float>(1.5 / focal),
      .focal_texel = static_cast<float>(focal * buffer.texel_size_m),
      .frame = view.frame_bgr,
      .depth = use_depth ? view.depth : view.frame_bgr,
      .depth_range = use_depth && view.depth_range && view.depth->isContinuous() &&
                             view.depth_range->isContinuous() &&
                             view.depth_range->size() == view.depth->size() &&
                             view.depth_range->type() == CV_32FC2
                         ? view.depth_range
                         : nullptr,
      .frame_step = static_cast<int32_t>(view.frame_bgr->step[0]),
      .depth_step = static_cast<int32_t>((use_depth ? view.depth : view.frame_bgr)->step[0]),
      .pyramid = &view.pyramid,
      .out_bgr = nullptr,
      .out_valid = nullptr,
      .out_quality = nullptr,
      .paint_bgra = nullptr,
      .paint_quality = nullptr,
      .rule = TexelUpdateRule()};
}

bool UsesDepth(const FrameView& view, const WarpOptions& options) {
  return options.occlusion.enabled && view.depth && !view.depth->empty();
}

// Every chunk of the buffer that is not culled, through `kernel`, in parallel; the counts
// summed (integers: the same whatever the order) and the tiles with visible texels. Runs of
// chunks (BaseBuffer::chunk_groups) outside the view are culled whole first.
Counts RunChunks(const KernelContext& k, ChunkKernel kernel, cv::Rect* visible_box) {
  const BaseBuffer& buffer = *k.buffer;
  std::mutex mutex;
  Counts total;
  cv::Rect box;
  const int num_chunks = static_cast<int>(buffer.chunks.size());
  const bool grouped = !buffer.chunk_groups.empty();
  const int num_items = grouped ? static_cast<int>(buffer.chunk_groups.size()) : num_chunks;
  const double stripes = std::max(1, std::min(num_items, 16 * cv::getNumThreads()));
  cv::parallel_for_(
      cv::Range(0, num_items),
      [&](const cv::Range& range) {
        Counts n;
        cv::Rect range_box;
        const auto run = [&](int first, int last) {
          for (int c = first; c < last; ++c) {
            const BaseBuffer::Chunk& chunk = buffer.chunks[c];
            if (ChunkOutsideView(k, chunk)) {
              ++n.culled;
              continue;
            }
            if (chunk.FacesAwayFrom(k.centre)) {  // every texel back-facing
              ++n.culled;
              n.grazing += chunk.end - chunk.begin;
              continue;
            }
            n.tested += chunk.end - chunk.begin;
            const int visible_before = n.visible;
            kernel(k, chunk, &n);
            if (n.visible > visible_before)
              range_box |= cv::Rect(chunk.x0, chunk.y0, chunk.x1 - chunk.x0, chunk.y1 - chunk.y0);
          }
        };
        for (int item = range.start; item < range.end; ++item) {
          if (!grouped) {
            run(item, item + 1);
            continue;
          }
          const BaseBuffer::ChunkGroup& group = buffer.chunk_groups[item];
          if (BoxOutsideView<float>(group.bounds_min, group.bounds_max, k.R, k.t, k.bounds,
                                    k.near_m)) {
            n.culled += group.last - group.first;
            continue;
          }
          run(group.first, group.last);
        }
        const std::lock_guard<std::mutex> lock(mutex);
        box |= range_box;
        total.in_view += n.in_view, total.visible += n.visible, total.occluded += n.occluded;
        total.grazing += n.grazing, total.culled += n.culled, total.tested += n.tested;
        total.paint.Add(n.paint);
      },
      stripes);
  *visible_box = box;
  return total;
}

void SetCounts(const Counts& n, WarpedBuffer* warped) {
  warped->in_view = n.in_view;
  warped->visible = n.visible;
  warped->occluded = n.occluded;
  warped->grazing = n.grazing;
  warped->chunks_culled = n.culled;
  warped->texels_tested = n.tested;
}

}  // namespace

void WarpFrameToBuffer(const BaseBuffer& buffer, const FrameView& view, const WarpOptions& options,
                       WarpedBuffer* warped) {
  const int w = buffer.width, h = buffer.height;
  const bool fresh =
      warped->bgr.rows != h || warped->bgr.cols != w || warped->valid.size() != warped->bgr.size();
  if (fresh) {
    warped->bgr.create(h, w, CV_8UC3);
    warped->valid.create(h, w, CV_8U);
    warped->quality.create(h, w, CV_32F);
    warped->valid.setTo(0);
    // Defined where not valid too: refinement's matching windows and interpolation reach
    // past the valid texels, and uninitialised memory made its results vary run to run.
    warped->bgr.setTo(0);
    warped->quality.setTo(0);
  } else if (!warped->valid_box.empty()) {
    // Valid texels lie inside valid_box (every writer keeps it so): clearing it clears all.
    warped->valid(warped->valid_box & cv::Rect(0, 0, w, h)).setTo(0);
  }
  const bool use_depth = UsesDepth(view, options);
  KernelContext k = MakeContext(buffer, view, options, use_depth);
  k.out_bgr = warped->bgr.data;
  k.out_valid = warped->valid.data;
  k.out_quality = warped->quality.ptr<float>();
  const Counts n =
      RunChunks(k, SelectKernel<false>(view.camera->HasDistortion(), use_depth, options.sampling),
                &warped->valid_box);
  SetCounts(n, warped);
}

PaintUpdateStats WarpAndPaintBuffer(const BaseBuffer& buffer, const FrameView& view,
                                    const WarpOptions& options, const TexelUpdateRule& rule,
                                    WarpedBuffer* counts, PaintedBuffer* painted) {
  const bool use_depth = UsesDepth(view, options);
  KernelContext k = MakeContext(buffer, view, options, use_depth);
  k.paint_bgra = painted->bgra.data;
  k.paint_quality = painted->quality.ptr<float>();
  k.rule = rule;
  const bool sums = rule.policy == UpdatePolicy::kMean || rule.mean_too;
  const bool fresh_sums = sums && painted->mean_sum.empty();
  if (sums) {
    AllocateSums(rule, painted);
    k.mean_sum = painted->mean_sum.ptr<float>();
    if (rule.mean_too) {
      k.held_sum = painted->held_sum.ptr<float>();
      k.shadow_bgra = painted->shadow_bgra.data;
      k.shadow_quality = painted->shadow_quality.ptr<float>();
      if (!painted->sharp_sum.empty()) {
        k.sharp_sum = painted->sharp_sum.ptr<float>();
        k.held_sharp_sum = painted->held_sharp_sum.ptr<float>();
      }
    }
  }
  cv::Rect visible_box;
  const Counts n =
      RunChunks(k, SelectKernel<true>(view.camera->HasDistortion(), use_depth, options.sampling),
                &visible_box);
  SetCounts(n, counts);
  painted->painted_surface_texels += n.paint.newly_painted;
  if (fresh_sums && n.visible == 0) {  // as PaintBuffer, which paints only buffers seen
    for (cv::Mat* m : {&painted->mean_sum, &painted->shadow_bgra, &painted->shadow_quality,
                       &painted->held_sum, &painted->sharp_sum, &painted->held_sharp_sum})
      m->release();
  }
  return n.paint;
}

}  // namespace fresco
