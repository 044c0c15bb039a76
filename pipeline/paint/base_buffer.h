// Base texture buffers (paper §2, eq. 2): each group of triangles gets a buffer with its
// own orthographic projection P_b onto the group's mean plane, so texels map one-to-one
// onto the surface. For every texel the 3D model point M = I_b P_b^-1 and its triangle are
// computed once, here. Texels just outside the triangles (a gutter of `gutter_texels`) take
// the closest point on the nearest triangle, so bilinear texture lookups at polygon edges
// never see unpainted texels. A group whose projection would fold (two triangles on one
// texel) is split until none does.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "pipeline/core/scene.h"
#include "pipeline/paint/grouping.h"

namespace fresco {

// A triangle must face the plane its texels lie in at least this much (cos 84 degrees: its
// texels stretched at most 10 times across it). Charts grow and merge under this bound
// (charts.cc), and a buffer moves out any triangle steeper to its plane, as it moves out a
// fold (BuildBaseBuffers).
constexpr double kMinPlaneCos = 0.1;

struct BaseBuffer {
  int id = -1;
  std::vector<int> triangles;
  // Plane frame in local coordinates: texel (i, j) has its centre at
  //   origin + (i + 0.5) * texel_size_m * axis_u + (j + 0.5) * texel_size_m * axis_v.
  // Looking at the surface from its front, axis_u points right and axis_v down.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis_u = Eigen::Vector3d::UnitX();
  Eigen::Vector3d axis_v = Eigen::Vector3d::UnitY();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double texel_size_m = 0.01;
  int width = 0, height = 0;

  // Texels that map onto the model (structure of arrays, K entries), in tile order: tiles
  // of kTileTexels x kTileTexels texels, row-major inside a tile, so that a run of texels is
  // a compact patch of the surface (cache-friendly in the frame, and cullable as a whole).
  std::vector<int32_t> texel_index;  // j * width + i
  // Model point and the unit normal of its triangle, as separate arrays so that the
  // per-frame kernel runs several texels per instruction, quantized to 16 bits: the point
  // within its chunk's bounding box (point = chunk.bounds_min + q * chunk.point_step per
  // axis, q in 0..65535: within 1/131070 of a 16-texel tile's extent), the normal as
  // n * 32767. 12 bytes per texel instead of 24.
  std::vector<uint16_t> point_qx, point_qy, point_qz;
  std::vector<int16_t> normal_qx, normal_qy, normal_qz;
  static constexpr float kNormalScale = 32767.0f;
  std::vector<uint8_t> on_surface;  // 1 inside a triangle, 0 gutter
  // (C) consecutive runs of texels, one per non-empty tile, with their bounding boxes
  // (local coordinates): a frame culls a whole chunk that lies outside its view.
  struct Chunk {
    int begin = 0, end = 0;  // [begin, end) into the texel arrays
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // the tile's texels: columns [x0, x1), rows [y0, y1)
    Eigen::Vector3f bounds_min = Eigen::Vector3f::Zero(), bounds_max = Eigen::Vector3f::Zero();
    Eigen::Vector3f point_step = Eigen::Vector3f::Zero();  // (bounds_max - bounds_min) / 65535
    // Every texel normal (as stored) lies within the cone around `normal_axis` (unit) of
    // half-angle acos(normal_cos) (sin: normal_sin); normal_cos 0, normal_sin 1 when the
    // normals spread over a half-space or more. A chunk all of whose texels face away from
    // the camera is culled whole.
    Eigen::Vector3f normal_axis = Eigen::Vector3f::Zero();
    float normal_cos = 0.0f, normal_sin = 1.0f;
    // A full tile (every texel of its rectangle stored, row by row) whose points lie on one
    // plane, affine in the texel coordinates to within one quantization step per axis:
    //   point(col, row) = affine_origin + col * affine_du + row * affine_dv
    // (col, row counted from x0, y0). The per-frame kernel then computes the points instead
    // of reading them, and when every texel has the same normal (`uniform_normal`: stored
    // as `normal`) reads no normal either: bandwidth the kernel would spend per texel.
    bool affine = false, uniform_normal = false;
    // Every texel of the rectangle stored, row by row (texel begin + r * (x1 - x0) + c is
    // column x0 + c of row y0 + r): a row of the tile is a run of the buffer's row.
    bool full = false;
    Eigen::Vector3f affine_origin = Eigen::Vector3f::Zero();
    Eigen::Vector3f affine_du = Eigen::Vector3f::Zero(), affine_dv = Eigen::Vector3f::Zero();
    Eigen::Vector3f normal = Eigen::Vector3f::Zero();  // as stored (dequantized)

    // True only when every texel of the chunk faces away from `centre` (its stored normal n
    // and point p have n . (centre - p) < 0): conservative, from the box and the cone.
    bool FacesAwayFrom(const Eigen::Vector3f& centre) const;
  };
  std::vector<Chunk> chunks;
  // Runs of kChunksPerGroup consecutive chunks (a strip of tiles) with their bounds: a frame
  // culls a whole run with one test. Empty for a buffer built by hand: chunks are then
  // tested one by one.
  struct ChunkGroup {
    int first = 0, last = 0;  // chunks [first, last)
    Eigen::Vector3f bounds_min = Eigen::Vector3f::Zero(), bounds_max = Eigen::Vector3f::Zero();
  };
  std::vector<ChunkGroup> chunk_groups;
  static constexpr int kChunksPerGroup = 16;
  static constexpr int kTileTexels = 16;
  int num_surface_texels = 0;
  Eigen::Vector3d bounds_min = Eigen::Vector3d::Zero(), bounds_max = Eigen::Vector3d::Zero();

  int NumTexels() const { return static_cast<int>(texel_index.size()); }
  // Texel k's model point (local coordinates) and normal, dequantized. PointIn takes the
  // chunk holding k (loops over chunks need no search); Point finds it.
  Eigen::Vector3f PointIn(const Chunk& chunk, int k) const {
    return chunk.bounds_min +
           Eigen::Vector3f(point_qx[k], point_qy[k], point_qz[k]).cwiseProduct(chunk.point_step);
  }
  Eigen::Vector3f Point(int k) const { return PointIn(ChunkOf(k), k); }
  Eigen::Vector3f Normal(int k) const {
    return Eigen::Vector3f(normal_qx[k], normal_qy[k], normal_qz[k]) / kNormalScale;
  }
  const Chunk& ChunkOf(int k) const;  // the chunk holding texel k
  // Texel coordinates (continuous, texel centres at i + 0.5) of a local point.
  Eigen::Vector2d TexelCoords(const Eigen::Vector3d& local_point) const;
};

// A group's buffer has at least this many texels across its longer side, whatever the
// texel size asked for (larger texels would miss the surface).
inline constexpr int kMinTexelsAcross = 4;

struct BaseBufferOptions {
  double texel_size_m = 0.01;       // default texel size (groups may override)
  int max_buffer_texels = 1 << 20;  // a bigger buffer gets coarser texels
  int max_side_texels = 1 << 30;    // so does one wider or higher (an atlas page's limit)
  int gutter_texels = 2;
  // Lay the buffers out only (the fold test and the surface texels counted): no texel arrays,
  // the buffers hollow as HollowBaseBuffers makes them (what a layout needs, for less).
  bool layout_only = false;
};

// How BuildBaseBuffers made one buffer, enough to make it again alone: the triangles it
// placed (in order; their mean plane, extent and bounds are the buffer's), those it moved out
// (their projection folded: they went to later buffers), the texel size its group asked for.
struct BufferRecipe {
  std::vector<int> placed;
  std::vector<int> folded;
  double group_texel_size_m = 0;  // GroupSpec::texel_size_m (0: the default)
  int num_surface_texels = 0;
};

// The buffers' layout without their texels (a shard builds only its own: pipeline/run/shard.h).
struct BufferLayout {
  double texel_size_m = 0;  // the session's default texel size
  int folds_split = 0;
  std::vector<BufferRecipe> recipes;  // one per buffer
};

struct BaseBufferSet {
  std::vector<BaseBuffer> buffers;
  Grouping grouping;    // after fold-over splits: buffers[g] serves grouping.groups[g]
  int folds_split = 0;  // groups split because their projection folded
  int scattered_split = 0;            // groups cut into compact pieces (SplitScatteredGroup)
  std::vector<BufferRecipe> recipes;  // buffers[b] is made by recipes[b]
};

// The buffer's plane axes for a group's mean `normal`: axis_v follows world down on walls,
// +z on floors and ceilings (sets normal, axis_u, axis_v).
void ChooseAxes(const Eigen::Vector3d& normal, BaseBuffer* buffer);

BaseBufferSet BuildBaseBuffers(const TriangleMesh& mesh, const Grouping& grouping,
                               const BaseBufferOptions& options);

// The buffers of `layout` without texels ("hollow": triangles, plane frame, size, bounds and
// num_surface_texels as BuildBaseBuffers makes them; no texel arrays), with the grouping and
// recipes. Cheap: only the triangles' corners are read. `options.texel_size_m` is ignored
// (the layout's).
BaseBufferSet HollowBaseBuffers(const TriangleMesh& mesh, const BufferLayout& layout,
                                BaseBufferOptions options);
// Buffer `b` of a set made by either, with its texels: the same as BuildBaseBuffers made it
// (`options.texel_size_m`: the layout's default texel size).
// Throws std::runtime_error when the recipe does not make the buffer it describes (another
// mesh).
BaseBuffer BuildLaidOutBuffer(const TriangleMesh& mesh, const BaseBufferSet& set, size_t b,
                              BaseBufferOptions options);

}  // namespace fresco
