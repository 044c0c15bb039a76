// A triangle scene loaded from glTF 2.0 (via tinygltf): all primitives of all nodes of the
// default scene, flattened into one triangle mesh with node transforms applied; or from PLY
// or OBJ (mesh_scene.h; LoadScene picks the reader by extension). Vertices are
// stored relative to a local origin (`origin_in_world`) so that map-scale coordinates
// (~1e6 m) keep their precision: world = local + origin_in_world.
#pragma once

#include <array>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "pipeline/core/status.h"

namespace fresco {

enum class TextureWrap { kRepeat, kClampToEdge, kMirroredRepeat };

struct Texture {
  cv::Mat rgba;  // CV_8UC4, sRGB values, row 0 = top of the image (glTF UV v = 0)
  TextureWrap wrap_s = TextureWrap::kRepeat;
  TextureWrap wrap_t = TextureWrap::kRepeat;
  std::string name;
};

struct Material {
  Eigen::Vector4d base_color_factor = Eigen::Vector4d::Ones();  // RGBA, linear factor
  int base_color_texture = -1;  // index into Scene::textures, -1 for none
  bool double_sided = false;
  std::string name;
};

struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices;            // local coordinates, metres
  std::vector<Eigen::Vector3i> triangles;           // vertex indices, counter-clockwise = front
  std::vector<std::array<Eigen::Vector2f, 3>> uvs;  // TEXCOORD_0 per corner (zeros if absent)
  std::vector<int> material;                        // per triangle, index into Scene::materials
  std::vector<bool> has_uv;                         // per triangle

  int NumTriangles() const { return static_cast<int>(triangles.size()); }
  Eigen::Vector3d Corner(int tri, int k) const { return vertices[triangles[tri][k]]; }
  // Unit normal (counter-clockwise winding), zero for a degenerate triangle.
  Eigen::Vector3d Normal(int tri) const;
  double Area(int tri) const;
};

// For each triangle, the triangles sharing each of its edges (edge k = corner k -> k+1).
// Vertices are welded by position (within `weld_tolerance_m`) first, so glTF meshes that
// duplicate vertices for UV seams are still connected. Non-manifold edges (3+ triangles)
// list every other triangle on the edge.
struct MeshAdjacency {
  // The other triangles on edge k of triangle t (from corner k to corner k + 1), sorted:
  // neighbours[offsets[3 t + k] .. offsets[3 t + k + 1]). One array for the whole mesh (a
  // list per edge cost a heap block each: 5 M of them at 1.8 M triangles).
  std::vector<int64_t> offsets;  // (3 T + 1)
  std::vector<int> neighbours;
  std::vector<int> welded_vertex;  // (V) canonical vertex index after welding

  int NumTriangles() const { return offsets.empty() ? 0 : static_cast<int>(offsets.size() / 3); }
  std::span<const int> EdgeNeighbours(int t, int k) const {
    return {neighbours.data() + offsets[3 * t + k], neighbours.data() + offsets[3 * t + k + 1]};
  }
  // The three edges' neighbours one after the other (a triangle may appear more than once).
  std::span<const int> Neighbours(int t) const {
    return {neighbours.data() + offsets[3 * t], neighbours.data() + offsets[3 * t + 3]};
  }
};
MeshAdjacency ComputeAdjacency(const TriangleMesh& mesh, double weld_tolerance_m = 1e-6);

// A view-dependent layer (pipeline.layers): the texture each material shows a viewer near the
// layer's cameras. Renderers that know layers blend them by the viewer's direction
// (view_dependent_render.h); others show the materials' base-colour textures.
struct ViewLayerTextures {
  Eigen::Vector3d centre_world = Eigen::Vector3d::Zero();  // mean camera centre of its frames
  std::vector<int> material_texture;  // per material: index into Scene::textures, -1 none
};

struct Scene {
  TriangleMesh mesh;
  std::vector<Material> materials;  // at least one (a default white material)
  std::vector<Texture> textures;
  std::vector<ViewLayerTextures> view_layers;  // none unless painted with pipeline.layers
  Eigen::Vector3d origin_in_world = Eigen::Vector3d::Zero();
  std::string source_path;
  // Filled by the loaders (informational; not written by SaveGltfScene).
  int dropped_degenerate = 0;         // triangles dropped: area < min_triangle_area_m2
  int skipped_primitives = 0;         // points / lines primitives (not triangles), skipped
  std::vector<std::string> warnings;  // one line each (reader warnings, skipped parts)

  Eigen::Vector3d LocalFromWorld(const Eigen::Vector3d& p) const { return p - origin_in_world; }
  Eigen::Vector3d WorldFromLocal(const Eigen::Vector3d& p) const { return p + origin_in_world; }
  // Axis-aligned bounds of the vertices, local coordinates.
  void Bounds(Eigen::Vector3d* min_corner, Eigen::Vector3d* max_corner) const;
};

struct SceneLoadOptions {
  // Drop triangles with area below this (m^2): degenerate triangles paint nothing.
  double min_triangle_area_m2 = 1e-14;
  // Local origin: the centre of the bounding box when true, (0,0,0) when false.
  bool recentre = true;
};

// Loads a scene file by its extension (case-insensitive): `.gltf`/`.glb` with LoadGltfScene,
// `.ply`/`.obj` with LoadMeshScene (mesh_scene.h); any other extension is an error naming the
// file and the formats read. Defined in mesh_scene.cc.
Status LoadScene(const std::string& path, const SceneLoadOptions& options, Scene* scene);

// Loads `.gltf` (with its .bin and images) or `.glb`. Errors name the file and what is wrong
// (missing file, parse error, out-of-range indices, no triangles).
// - Geometry: the default scene (else scene 0, else every root node), node transforms
//   composed in double; TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN primitives (points and
//   lines are skipped and counted); u8/u16/u32 indices, strided, normalized and sparse
//   accessors. Mirroring node transforms get their winding flipped (CCW stays front).
//   Only vertices used by kept triangles are stored, in accessor order, per primitive.
// - UVs: the set the material's base colour texture uses (normally TEXCOORD_0), unflipped.
// - Materials: 1:1 with the file's, plus a default white one ("default") appended when a
//   primitive has none. Textures: those used as baseColorTexture, in the file's texture
//   order, decoded to RGBA8 (16-bit images scaled, grey/RGB expanded).
Status LoadGltfScene(const std::string& path, const SceneLoadOptions& options, Scene* scene);
// The same from the file's bytes already in memory (GLB when they start with "glTF", else
// glTF JSON); relative URIs resolve against `base_dir`, and `path` names the source in
// messages and becomes Scene::source_path.
Status ParseGltfScene(const std::string& bytes, const std::string& path,
                      const std::string& base_dir, const SceneLoadOptions& options, Scene* scene);

// Writes `scene` as glTF 2.0 (`.gltf` + `.bin` + one PNG per texture beside it), atomically
// per file. Geometry is written in world coordinates relative to origin via a node
// translation, so map-scale scenes keep precision.
// Round trip: LoadGltfScene gives back the same triangles (same order), UVs, materials and
// texels exactly; vertices are stored as float relative to the origin (exact when they are
// floats), one vertex set per run of triangles with equal material and UV presence (a vertex
// with different UVs on different corners is duplicated). With recentre, the reloaded origin
// is the bounding-box centre. Textures no material or layer uses are written but not loaded
// back, and an empty texture name comes back as the PNG's file name. View-dependent layers go
// in the file's `FRESCO_view_layers` extension (extensionsUsed, not required: other viewers
// show the base-colour textures): {"layers": [{"centre": [x, y, z] (world), "textures": [per
// material a texture index or -1]}]}; a malformed one is dropped with a warning on loading.
// Errors: a scene that cannot be saved (not finite, indices out of range) is internal, a
// failed write is output.
Status SaveGltfScene(const Scene& scene, const std::string& path);
// Only the PNG files SaveGltfScene(scene, path) writes beside `path` (the same names and bytes),
// no .gltf or .bin: e.g. the pages of a shard's part whose glTF another part holds.
Status SaveGltfTextures(const Scene& scene, const std::string& path);

}  // namespace fresco
