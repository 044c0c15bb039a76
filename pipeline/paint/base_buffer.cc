#include "pipeline/paint/base_buffer.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_set>

#include <opencv2/core.hpp>

#include "pipeline/paint/scattered_groups.h"
#include "pipeline/paint/texel_span.h"

namespace fresco {
namespace {

// The cone holding the chunk's stored normals (as the warp dequantizes them), with a margin
// for float rounding; none when they spread over 80 degrees or more from their mean.
void SetNormalCone(const BaseBuffer& buffer, BaseBuffer::Chunk* chunk) {
  Eigen::Vector3f mean = Eigen::Vector3f::Zero();
  for (int k = chunk->begin; k < chunk->end; ++k) mean += buffer.Normal(k).normalized();
  if (!(mean.norm() > 0.0f)) return;
  const Eigen::Vector3f axis = mean.normalized();
  float min_cos = 1.0f;
  for (int k = chunk->begin; k < chunk->end; ++k)
    min_cos = std::min(min_cos, axis.dot(buffer.Normal(k).normalized()));
  const double half_angle = std::acos(std::clamp(static_cast<double>(min_cos), -1.0, 1.0)) + 1e-3;
  if (half_angle >= 80.0 * M_PI / 180.0) return;
  chunk->normal_axis = axis;
  chunk->normal_cos = static_cast<float>(std::cos(half_angle));
  chunk->normal_sin = static_cast<float>(std::sin(half_angle));
}

// Marks a tile whose rectangle is stored whole, row by row (BaseBuffer::Chunk::full).
void SetFullTile(const BaseBuffer& buffer, BaseBuffer::Chunk* chunk) {
  const int tw = chunk->x1 - chunk->x0, th = chunk->y1 - chunk->y0;
  if (chunk->end - chunk->begin != tw * th) return;
  for (int row = 0, k = chunk->begin; row < th; ++row)
    for (int col = 0; col < tw; ++col, ++k)
      if (buffer.texel_index[k] != (chunk->y0 + row) * buffer.width + chunk->x0 + col) return;
  chunk->full = true;
}

// Marks a full tile whose stored points are affine in the texel coordinates (least squares
// over the tile, every texel within one quantization step per axis), and whose normals are
// all the same (BaseBuffer::Chunk::affine, uniform_normal).
void SetAffineTile(const BaseBuffer& buffer, BaseBuffer::Chunk* chunk) {
  const int tw = chunk->x1 - chunk->x0, th = chunk->y1 - chunk->y0;
  if (chunk->end - chunk->begin != tw * th) return;
  bool same_normal = true;
  for (int k = chunk->begin + 1; k < chunk->end && same_normal; ++k)
    same_normal = buffer.normal_qx[k] == buffer.normal_qx[chunk->begin] &&
                  buffer.normal_qy[k] == buffer.normal_qy[chunk->begin] &&
                  buffer.normal_qz[k] == buffer.normal_qz[chunk->begin];
  if (same_normal) {
    chunk->uniform_normal = true;
    chunk->normal = buffer.Normal(chunk->begin);
  }
  if (tw != BaseBuffer::kTileTexels || th < 2) return;  // the kernel's layout: 16 columns
  // Least squares of p = origin + col du + row dv over the full grid, in closed form (col
  // and row are uncorrelated on a full grid: each slope is a plain regression).
  const double mean_col = 0.5 * (tw - 1), mean_row = 0.5 * (th - 1);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero(), by_col = Eigen::Vector3d::Zero(),
                  by_row = Eigen::Vector3d::Zero();
  for (int row = 0, k = chunk->begin; row < th; ++row)
    for (int col = 0; col < tw; ++col, ++k) {
      const Eigen::Vector3d p = buffer.PointIn(*chunk, k).cast<double>();
      mean += p;
      by_col += (col - mean_col) * p;
      by_row += (row - mean_row) * p;
    }
  const double count = static_cast<double>(tw) * th;
  mean /= count;
  const double col_var = count * (static_cast<double>(tw) * tw - 1) / 12.0;
  const double row_var = count * (static_cast<double>(th) * th - 1) / 12.0;
  const Eigen::Vector3f du = (by_col / col_var).cast<float>();
  const Eigen::Vector3f dv = (by_row / row_var).cast<float>();
  const Eigen::Vector3f origin =
      (mean - mean_col * by_col / col_var - mean_row * by_row / row_var).cast<float>();
  // Within one quantization step per axis (and a float's rounding) of every stored point.
  const Eigen::Array3f bound =
      chunk->point_step.array() + 1e-6f * chunk->bounds_max.cwiseAbs().array();
  for (int row = 0, k = chunk->begin; row < th; ++row)
    for (int col = 0; col < tw; ++col, ++k) {
      const Eigen::Vector3f fit =
          origin + static_cast<float>(col) * du + static_cast<float>(row) * dv;
      if (((fit - buffer.PointIn(*chunk, k)).cwiseAbs().array() > bound).any()) return;
    }
  chunk->affine = true;
  chunk->affine_origin = origin;
  chunk->affine_du = du;
  chunk->affine_dv = dv;
}

// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
Eigen::Vector3d ClosestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                       const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

struct PlaneCoords {
  double a_min = 1e300, a_max = -1e300, b_min = 1e300, b_max = -1e300;
};

// The triangles' corners along the buffer's axes from `anchor`; sets the buffer's bounds.
PlaneCoords PlaneExtent(const TriangleMesh& mesh, const std::vector<int>& triangles,
                        const Eigen::Vector3d& anchor, BaseBuffer* buffer) {
  PlaneCoords pc;
  buffer->bounds_min = Eigen::Vector3d::Constant(1e300);
  buffer->bounds_max = Eigen::Vector3d::Constant(-1e300);
  for (int t : triangles) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d p = mesh.Corner(t, k);
      buffer->bounds_min = buffer->bounds_min.cwiseMin(p);
      buffer->bounds_max = buffer->bounds_max.cwiseMax(p);
      const double a = (p - anchor).dot(buffer->axis_u), b = (p - anchor).dot(buffer->axis_v);
      pc.a_min = std::min(pc.a_min, a), pc.a_max = std::max(pc.a_max, a);
      pc.b_min = std::min(pc.b_min, b), pc.b_max = std::max(pc.b_max, b);
    }
  }
  return pc;
}

// The buffer's texel size, width, height and origin for the extent `pc` (from `anchor`):
// texels of texel_size_m, larger where the buffer would exceed the options' caps.
void SizeTexels(const PlaneCoords& pc, const Eigen::Vector3d& anchor, double texel_size_m,
                const BaseBufferOptions& options, BaseBuffer* buffer) {
  const int gutter = options.gutter_texels;
  // Texels larger than the group would leave no texel centre on it (never painted): at
  // least kMinTexelsAcross texels across its longer side.
  const double extent = std::max(pc.a_max - pc.a_min, pc.b_max - pc.b_min);
  double s = extent > 0 ? std::min(texel_size_m, extent / kMinTexelsAcross) : texel_size_m;
  // In double: a tiny texel size would overflow int before the cap applies.
  double wd = 0, hd = 0;
  auto dims = [&](double size) {
    wd = std::ceil((pc.a_max - pc.a_min) / size) + 2 * gutter + 1;
    hd = std::ceil((pc.b_max - pc.b_min) / size) + 2 * gutter + 1;
  };
  dims(s);
  const double max_side = options.max_side_texels;
  for (int iter = 0;
       iter < 60 && (wd * hd > options.max_buffer_texels || wd > max_side || hd > max_side);
       ++iter) {
    // The gutter does not scale with the texel: aim at what the interior may take.
    const double inner = 2.0 * gutter + 1;
    s *= std::max({std::sqrt(wd * hd / options.max_buffer_texels),
                   (wd - inner) / std::max(1.0, max_side - inner),
                   (hd - inner) / std::max(1.0, max_side - inner), 1.0}) *
         1.01;
    dims(s);
  }
  buffer->texel_size_m = s;
  buffer->width = static_cast<int>(wd);
  buffer->height = static_cast<int>(hd);
  buffer->origin =
      anchor + (pc.a_min - gutter * s) * buffer->axis_u + (pc.b_min - gutter * s) * buffer->axis_v;
}

// Texel (i, j)'s centre on the buffer's plane.
Eigen::Vector3d PlanePoint(const BaseBuffer& buffer, int i, int j) {
  const double s = buffer.texel_size_m;
  return buffer.origin + ((i + 0.5) * s) * buffer.axis_u + ((j + 0.5) * s) * buffer.axis_v;
}

// The texels of a buffer being built. owner: the texel's triangle as its position in the
// buffer's triangle list (-1: none); per-buffer arrays are indexed by that position, never
// by the mesh's triangle id (10^4 charts of a 10^6 triangle mesh would otherwise clear 10^10
// flags). point: the texel's point on that triangle.
struct TexelOwners {
  std::vector<int32_t> owner;
  std::vector<Eigen::Vector3f> point;
  // Laying out only (nothing but the folds and the count is kept): `point` holds only the
  // slivers' centroids, the texels in `sliver`; any other owned texel's point is worked out
  // again from its triangle (`corner0` and `normal`, by position in the buffer's list) where
  // another triangle covers its centre, the same in every bit.
  bool points_on_demand = false;
  std::unordered_set<size_t> sliver;
  std::vector<Eigen::Vector3d> corner0, normal;
};

// Texel (i, j)'s centre on the buffer's plane moved along the buffer's normal onto the plane
// of the triangle through `corner` with normal `normal`.
Eigen::Vector3d PointOver(const BaseBuffer& buffer, int i, int j, const Eigen::Vector3d& corner,
                          const Eigen::Vector3d& normal) {
  const Eigen::Vector3d pp = PlanePoint(buffer, i, j);
  return pp + buffer.normal * ((corner - pp).dot(normal) / buffer.normal.dot(normal));
}

// The point texel `idx` = (i, j) holds (it has an owner).
Eigen::Vector3f HeldPoint(const BaseBuffer& buffer, const TexelOwners& texels, size_t idx, int i,
                          int j) {
  if (!texels.points_on_demand || texels.sliver.count(idx)) return texels.point[idx];
  const int li = texels.owner[idx];
  return PointOver(buffer, i, j, texels.corner0[li], texels.normal[li]).cast<float>();
}

// One triangle as placed on the buffer: its position in the buffer's list, its corners in
// texel coordinates and in the mesh, and its normal.
struct PlacedTriangle {
  int li = 0;
  Eigen::Vector2d q[3];
  double sign = 1;  // of the texel-coordinate area
  Eigen::Vector3d corner[3];
  Eigen::Vector3d normal;
};

// Gives the triangle the free texels whose centres it covers, at their points on it
// (along the buffer's normal); where another triangle holds a texel at another point, the
// projection folds and `folded` is set. Returns whether it covers any texel centre.
bool CoverCentres(const BaseBuffer& buffer, const PlacedTriangle& tri, TexelOwners* texels,
                  uint8_t* folded) {
  const Eigen::Vector2d* q = tri.q;
  const int w = buffer.width, h = buffer.height;
  const double s = buffer.texel_size_m;
  const int i0 =
      std::max(0, static_cast<int>(std::floor(std::min({q[0].x(), q[1].x(), q[2].x()}) - 0.5)));
  const int i1 =
      std::min(w - 1, static_cast<int>(std::ceil(std::max({q[0].x(), q[1].x(), q[2].x()}) - 0.5)));
  const int j0 =
      std::max(0, static_cast<int>(std::floor(std::min({q[0].y(), q[1].y(), q[2].y()}) - 0.5)));
  const int j1 =
      std::min(h - 1, static_cast<int>(std::ceil(std::max({q[0].y(), q[1].y(), q[2].y()}) - 0.5)));
  bool covers_a_centre = false;
  for (int j = j0; j <= j1; ++j) {
    int lo = 0, hi = -1;
    CentresInsideRow(tri.q, tri.sign, j, i0, i1, &lo, &hi);
    for (int i = lo; i <= hi; ++i) {
      covers_a_centre = true;
      const size_t idx = static_cast<size_t>(j) * w + i;
      if (texels->owner[idx] >= 0) {
        // Shared edge: same point. Different point: the projection folds here.
        const Eigen::Vector3d m = PointOver(buffer, i, j, tri.corner[0], tri.normal);
        if ((HeldPoint(buffer, *texels, idx, i, j).cast<double>() - m).norm() > 0.5 * s)
          *folded = 1;
        continue;
      }
      texels->owner[idx] = tri.li;
      if (!texels->points_on_demand)
        texels->point[idx] = PointOver(buffer, i, j, tri.corner[0], tri.normal).cast<float>();
    }
  }
  return covers_a_centre;
}

// Places triangle li of the buffer's list on its texels; `folded` is set where it cannot
// serve them (edge-on, back-facing or folding over others).
void PlaceTriangle(const TriangleMesh& mesh, const BaseBuffer& buffer, int li,
                   const Eigen::Vector3d& normal, TexelOwners* texels, uint8_t* folded) {
  const int t = buffer.triangles[li];
  // Near edge-on or back-facing: it cannot serve the buffer well.
  if (normal.dot(buffer.normal) < kMinPlaneCos) {
    *folded = 1;
    return;
  }
  PlacedTriangle tri;
  tri.li = li;
  tri.normal = normal;
  Eigen::Vector2d* q = tri.q;
  for (int k = 0; k < 3; ++k) q[k] = buffer.TexelCoords(mesh.Corner(t, k));
  const double area2 =
      (q[1] - q[0]).x() * (q[2] - q[0]).y() - (q[1] - q[0]).y() * (q[2] - q[0]).x();
  if (std::abs(area2) < 1e-18) return;
  tri.sign = area2 > 0 ? 1.0 : -1.0;
  for (int k = 0; k < 3; ++k) tri.corner[k] = mesh.Corner(t, k);
  if (CoverCentres(buffer, tri, texels, folded)) return;
  // A sliver thinner than a texel: the texel under its centroid, if free, serves it
  // (at the centroid, which lies on it), so that no triangle goes unpainted.
  const Eigen::Vector2d c = (q[0] + q[1] + q[2]) / 3.0;
  const int i = std::clamp(static_cast<int>(std::floor(c.x())), 0, buffer.width - 1);
  const int j = std::clamp(static_cast<int>(std::floor(c.y())), 0, buffer.height - 1);
  const size_t idx = static_cast<size_t>(j) * buffer.width + i;
  if (texels->owner[idx] < 0) {
    texels->owner[idx] = li;
    texels->point[idx] =
        ((mesh.Corner(t, 0) + mesh.Corner(t, 1) + mesh.Corner(t, 2)) / 3.0).cast<float>();
    if (texels->points_on_demand) texels->sliver.insert(idx);
  }
}

// Gutter: dilate ownership ring by ring; a gutter texel takes the closest point on the
// neighbouring texel's triangle.
void GrowGutter(const TriangleMesh& mesh, const BaseBuffer& buffer, int gutter,
                TexelOwners* texels) {
  const int w = buffer.width, h = buffer.height;
  std::vector<int32_t>& owner = texels->owner;
  for (int ring = 0; ring < gutter; ++ring) {
    std::vector<int32_t> next = owner;
    for (int j = 0; j < h; ++j) {
      for (int i = 0; i < w; ++i) {
        const size_t idx = static_cast<size_t>(j) * w + i;
        if (owner[idx] >= 0) continue;
        int best = -1;
        for (int dj = -1; dj <= 1 && best < 0; ++dj)
          for (int di = -1; di <= 1 && best < 0; ++di) {
            const int ii = i + di, jj = j + dj;
            if (ii < 0 || jj < 0 || ii >= w || jj >= h) continue;
            best = owner[static_cast<size_t>(jj) * w + ii];
          }
        if (best < 0) continue;
        next[idx] = best;
        const int t = buffer.triangles[best];
        texels->point[idx] = ClosestPointOnTriangle(PlanePoint(buffer, i, j), mesh.Corner(t, 0),
                                                    mesh.Corner(t, 1), mesh.Corner(t, 2))
                                 .cast<float>();
      }
    }
    owner.swap(next);
  }
}

// A coordinate quantized over [min, min + 65535 step], rounded (0 where the step is 0).
uint16_t QuantizePoint(float value, float min, float step) {
  if (!(step > 0.0f)) return uint16_t{0};
  const float q = (value - min) / step;
  return static_cast<uint16_t>(std::clamp(q, 0.0f, 65535.0f) + 0.5f);  // rounded
}

// A normal's component in kNormalScale steps, rounded half away from zero.
int16_t QuantizeNormal(double value) {
  const double q = std::clamp(value, -1.0, 1.0) * BaseBuffer::kNormalScale;
  return static_cast<int16_t>(q >= 0 ? q + 0.5 : q - 0.5);
}

// Stores the owned texels of the tile at (ti, tj) as the buffer's next chunk (quantized
// within the tile's bounds), with its cone and layout flags; an empty tile stores nothing.
void StoreTile(const TexelOwners& texels, const std::vector<uint8_t>& surface,
               const std::vector<Eigen::Vector3d>& normal_of, int ti, int tj, BaseBuffer* buffer) {
  const int tile = BaseBuffer::kTileTexels;
  const int w = buffer->width, h = buffer->height;
  const std::vector<int32_t>& owner = texels.owner;
  const std::vector<Eigen::Vector3f>& point = texels.point;
  BaseBuffer::Chunk chunk;
  chunk.begin = buffer->NumTexels();
  chunk.x0 = ti, chunk.y0 = tj, chunk.x1 = std::min(ti + tile, w),
  chunk.y1 = std::min(tj + tile, h);
  chunk.bounds_min = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  chunk.bounds_max = -chunk.bounds_min;
  const int j1 = std::min(tj + tile, h), i1 = std::min(ti + tile, w);
  for (int j = tj; j < j1; ++j) {
    for (int i = ti; i < i1; ++i) {
      const size_t idx = static_cast<size_t>(j) * w + i;
      if (owner[idx] < 0) continue;
      chunk.bounds_min = chunk.bounds_min.cwiseMin(point[idx]);
      chunk.bounds_max = chunk.bounds_max.cwiseMax(point[idx]);
    }
  }
  chunk.point_step = (chunk.bounds_max - chunk.bounds_min) / 65535.0f;
  for (int j = tj; j < j1; ++j) {
    for (int i = ti; i < i1; ++i) {
      const size_t idx = static_cast<size_t>(j) * w + i;
      if (owner[idx] < 0) continue;
      buffer->texel_index.push_back(static_cast<int32_t>(idx));
      buffer->point_qx.push_back(
          QuantizePoint(point[idx][0], chunk.bounds_min[0], chunk.point_step[0]));
      buffer->point_qy.push_back(
          QuantizePoint(point[idx][1], chunk.bounds_min[1], chunk.point_step[1]));
      buffer->point_qz.push_back(
          QuantizePoint(point[idx][2], chunk.bounds_min[2], chunk.point_step[2]));
      const Eigen::Vector3d& n = normal_of[owner[idx]];
      buffer->normal_qx.push_back(QuantizeNormal(n.x()));
      buffer->normal_qy.push_back(QuantizeNormal(n.y()));
      buffer->normal_qz.push_back(QuantizeNormal(n.z()));
      buffer->on_surface.push_back(surface[idx]);
      buffer->num_surface_texels += surface[idx];
    }
  }
  chunk.end = buffer->NumTexels();
  SetNormalCone(*buffer, &chunk);
  SetFullTile(*buffer, &chunk);
  SetAffineTile(*buffer, &chunk);
  if (chunk.end > chunk.begin) buffer->chunks.push_back(chunk);
}

// Groups of kChunksPerGroup consecutive chunks with their joint bounds.
void GroupChunks(BaseBuffer* buffer) {
  const int num_chunks = static_cast<int>(buffer->chunks.size());
  for (int first = 0; first < num_chunks; first += BaseBuffer::kChunksPerGroup) {
    BaseBuffer::ChunkGroup group;
    group.first = first;
    group.last = std::min(num_chunks, first + BaseBuffer::kChunksPerGroup);
    group.bounds_min = buffer->chunks[first].bounds_min;
    group.bounds_max = buffer->chunks[first].bounds_max;
    for (int c = first + 1; c < group.last; ++c) {
      group.bounds_min = group.bounds_min.cwiseMin(buffer->chunks[c].bounds_min);
      group.bounds_max = group.bounds_max.cwiseMax(buffer->chunks[c].bounds_max);
    }
    buffer->chunk_groups.push_back(group);
  }
}

// The buffer's plane frame, bounds and size for `triangles` (no texels).
void FrameBuffer(const TriangleMesh& mesh, const std::vector<int>& triangles, double texel_size_m,
                 const BaseBufferOptions& options, BaseBuffer* buffer) {
  BaseBufferGroup group;
  group.triangles = triangles;
  ChooseAxes(GroupNormal(mesh, group), buffer);
  const Eigen::Vector3d anchor = mesh.Corner(triangles[0], 0);
  const PlaneCoords pc = PlaneExtent(mesh, triangles, anchor, buffer);
  SizeTexels(pc, anchor, texel_size_m, options, buffer);
}

// The triangles a recipe's buffer keeps (placed less folded, in order).
std::vector<int> KeptTriangles(const BufferRecipe& recipe) {
  if (recipe.folded.empty()) return recipe.placed;
  const std::unordered_set<int> folded(recipe.folded.begin(), recipe.folded.end());
  std::vector<int> kept;
  for (int t : recipe.placed)
    if (!folded.count(t)) kept.push_back(t);
  return kept;
}

// Builds one buffer; triangles whose projection folds over others are returned in `folded`.
BaseBuffer BuildOne(const TriangleMesh& mesh, const std::vector<int>& triangles,
                    double texel_size_m, const BaseBufferOptions& options,
                    std::vector<int>* folded) {
  BaseBuffer buffer;
  buffer.triangles = triangles;
  FrameBuffer(mesh, triangles, texel_size_m, options, &buffer);
  const int w = buffer.width, h = buffer.height;

  const int num_local = static_cast<int>(triangles.size());
  TexelOwners texels;
  texels.owner.assign(static_cast<size_t>(w) * h, -1);
  texels.point.resize(static_cast<size_t>(w) * h);
  std::vector<uint8_t> is_folded(num_local, 0);
  std::vector<Eigen::Vector3d> normal_of(num_local);
  for (int li = 0; li < num_local; ++li) normal_of[li] = mesh.Normal(triangles[li]);
  if (options.layout_only) {
    texels.points_on_demand = true;
    texels.normal = normal_of;
    texels.corner0.resize(num_local);
    for (int li = 0; li < num_local; ++li) texels.corner0[li] = mesh.Corner(triangles[li], 0);
  }
  for (int li = 0; li < num_local; ++li)
    PlaceTriangle(mesh, buffer, li, normal_of[li], &texels, &is_folded[li]);
  for (int li = 0; li < num_local; ++li)
    if (is_folded[li]) folded->push_back(triangles[li]);
  std::vector<int32_t>& owner = texels.owner;
  if (!folded->empty()) {
    // Drop folded triangles' texels; they go to another buffer.
    for (size_t idx = 0; idx < owner.size(); ++idx)
      if (owner[idx] >= 0 && is_folded[owner[idx]]) owner[idx] = -1;
  }
  std::vector<uint8_t> surface(owner.size(), 0);
  for (size_t idx = 0; idx < owner.size(); ++idx) surface[idx] = owner[idx] >= 0;
  if (options.layout_only) {
    buffer.num_surface_texels = static_cast<int>(std::count(surface.begin(), surface.end(), 1));
    return buffer;
  }

  GrowGutter(mesh, buffer, options.gutter_texels, &texels);
  const int tile = BaseBuffer::kTileTexels;
  for (int tj = 0; tj < h; tj += tile)
    for (int ti = 0; ti < w; ti += tile) StoreTile(texels, surface, normal_of, ti, tj, &buffer);
  GroupChunks(&buffer);
  return buffer;
}

}  // namespace

void ChooseAxes(const Eigen::Vector3d& normal, BaseBuffer* buffer) {
  // Image "down" follows world down (glTF +Y up) on walls; on floors and ceilings +Z.
  Eigen::Vector3d down(0, -1, 0);
  Eigen::Vector3d v = down - normal * normal.dot(down);
  if (v.norm() < 0.3) {
    const Eigen::Vector3d z(0, 0, 1);
    v = z - normal * normal.dot(z);
  }
  buffer->normal = normal;
  buffer->axis_v = v.normalized();
  buffer->axis_u = normal.cross(buffer->axis_v).normalized();
}

// For a normal n within the chunk's cone (axis a, half-angle h) and d = c - p from a point p
// in the box, n.d <= cos(h) a.d + sin(h) |d|, whose maximum over the box is at most the sum
// of the two terms' maxima over its corners (a.d is linear in p, |d| convex).
bool BaseBuffer::Chunk::FacesAwayFrom(const Eigen::Vector3f& c) const {
  if (normal_sin >= 1.0f) return false;
  float max_ad = -std::numeric_limits<float>::infinity(), max_d2 = 0.0f;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3f corner((i & 1) ? bounds_max.x() : bounds_min.x(),
                                 (i & 2) ? bounds_max.y() : bounds_min.y(),
                                 (i & 4) ? bounds_max.z() : bounds_min.z());
    const Eigen::Vector3f d = c - corner;
    max_ad = std::max(max_ad, normal_axis.dot(d));
    max_d2 = std::max(max_d2, d.squaredNorm());
  }
  const float max_d = std::sqrt(max_d2);  // sqrt is monotonic: the largest |d|, one root
  // The margin covers float rounding in the texels' own test (relative 1e-5 of |d|).
  return normal_cos * max_ad + normal_sin * max_d < -1e-5f * max_d;
}

const BaseBuffer::Chunk& BaseBuffer::ChunkOf(int k) const {
  const auto it = std::upper_bound(chunks.begin(), chunks.end(), k,
                                   [](int texel, const Chunk& c) { return texel < c.begin; });
  return *std::prev(it);
}

Eigen::Vector2d BaseBuffer::TexelCoords(const Eigen::Vector3d& local_point) const {
  const Eigen::Vector3d d = local_point - origin;
  return Eigen::Vector2d(d.dot(axis_u) / texel_size_m, d.dot(axis_v) / texel_size_m);
}

BaseBufferSet BuildBaseBuffers(const TriangleMesh& mesh, const Grouping& grouping,
                               const BaseBufferOptions& options) {
  BaseBufferSet set;
  // Each group, and each part a fold splits off, in compact pieces (scattered_groups.h).
  std::deque<BaseBufferGroup> pending;
  const auto add_pending = [&](const BaseBufferGroup& group) {
    const double s = group.texel_size_m > 0 ? group.texel_size_m : options.texel_size_m;
    std::vector<BaseBufferGroup> pieces =
        SplitScatteredGroup(mesh, group, s, options.gutter_texels);
    if (pieces.size() > 1) ++set.scattered_split;
    for (BaseBufferGroup& piece : pieces) pending.push_back(std::move(piece));
  };
  for (const BaseBufferGroup& group : grouping.groups) add_pending(group);
  // The groups pending are built in waves, in parallel, then taken in order: the groups split
  // off go to the back, so the order is the one building them one by one gives.
  std::deque<BaseBuffer> built;
  std::deque<std::vector<int>> built_folded;
  while (!pending.empty()) {
    if (built.empty()) {
      const int wave = static_cast<int>(pending.size());
      built.resize(wave);
      built_folded.resize(wave);
      cv::parallel_for_(
          cv::Range(0, wave),
          [&](const cv::Range& range) {
            for (int g = range.start; g < range.end; ++g) {
              const BaseBufferGroup& group = pending[g];
              if (group.triangles.empty()) continue;
              const double s = group.texel_size_m > 0 ? group.texel_size_m : options.texel_size_m;
              built[g] = BuildOne(mesh, group.triangles, s, options, &built_folded[g]);
            }
          },
          wave);
    }
    BaseBufferGroup group = pending.front();
    pending.pop_front();
    BaseBuffer buffer = std::move(built.front());
    std::vector<int> folded = std::move(built_folded.front()), placed = group.triangles;
    built.pop_front();
    built_folded.pop_front();
    if (group.triangles.empty()) continue;
    if (!folded.empty()) {
      if (folded.size() == group.triangles.size()) {
        // Nothing in this group can be served by its own mean plane (e.g. opposite
        // normals): split in halves so the recursion ends.
        if (folded.size() == 1) continue;  // degenerate: never painted
        BaseBufferGroup a = group, b = group;
        a.triangles.assign(folded.begin(), folded.begin() + folded.size() / 2);
        b.triangles.assign(folded.begin() + folded.size() / 2, folded.end());
        add_pending(a);
        add_pending(b);
        ++set.folds_split;
        continue;
      }
      const std::unordered_set<int> folded_set(folded.begin(), folded.end());
      std::vector<int> kept;
      for (int t : group.triangles)
        if (!folded_set.count(t)) kept.push_back(t);
      group.triangles = kept;
      buffer.triangles = kept;
      BaseBufferGroup rest = group;
      rest.triangles = folded;
      add_pending(rest);
      ++set.folds_split;
    }
    buffer.id = static_cast<int>(set.buffers.size());
    BufferRecipe recipe;
    recipe.placed = std::move(placed);
    recipe.folded = std::move(folded);
    recipe.group_texel_size_m = group.texel_size_m;
    recipe.num_surface_texels = buffer.num_surface_texels;
    set.recipes.push_back(std::move(recipe));
    set.grouping.groups.push_back(group);
    set.buffers.push_back(std::move(buffer));
  }
  set.grouping.RebuildIndex(mesh.NumTriangles());
  return set;
}

BaseBufferSet HollowBaseBuffers(const TriangleMesh& mesh, const BufferLayout& layout,
                                BaseBufferOptions options) {
  options.texel_size_m = layout.texel_size_m;
  BaseBufferSet set;
  set.folds_split = layout.folds_split;
  set.recipes = layout.recipes;
  for (const BufferRecipe& recipe : layout.recipes) {
    BaseBuffer buffer;
    buffer.id = static_cast<int>(set.buffers.size());
    buffer.triangles = KeptTriangles(recipe);
    const double s =
        recipe.group_texel_size_m > 0 ? recipe.group_texel_size_m : options.texel_size_m;
    FrameBuffer(mesh, recipe.placed, s, options, &buffer);
    buffer.num_surface_texels = recipe.num_surface_texels;
    GroupSpec group;
    group.triangles = buffer.triangles;
    group.texel_size_m = recipe.group_texel_size_m;
    set.grouping.groups.push_back(std::move(group));
    set.buffers.push_back(std::move(buffer));
  }
  set.grouping.RebuildIndex(mesh.NumTriangles());
  return set;
}

BaseBuffer BuildLaidOutBuffer(const TriangleMesh& mesh, const BaseBufferSet& set, size_t b,
                              BaseBufferOptions options) {
  options.layout_only = false;
  const BufferRecipe& recipe = set.recipes.at(b);
  const double s = recipe.group_texel_size_m > 0 ? recipe.group_texel_size_m : options.texel_size_m;
  std::vector<int> folded;
  BaseBuffer buffer = BuildOne(mesh, recipe.placed, s, options, &folded);
  if (folded != recipe.folded || buffer.num_surface_texels != recipe.num_surface_texels)
    throw std::runtime_error("BuildLaidOutBuffer: buffer " + std::to_string(b) +
                             " is not the one its recipe describes (another mesh?)");
  buffer.id = static_cast<int>(b);
  buffer.triangles = KeptTriangles(recipe);
  return buffer;
}

}  // namespace fresco
