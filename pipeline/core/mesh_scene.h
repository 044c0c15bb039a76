// Triangle scenes from the mesh formats photogrammetry and scanning tools write: PLY (binary
// or ASCII) and OBJ (+ MTL), read through Assimp into the same `Scene` as LoadGltfScene.
// LoadScene (scene.h) chooses between this and glTF by the file's extension.
#pragma once

#include <string>

#include "pipeline/core/scene.h"
#include "pipeline/core/status.h"

namespace fresco {

// Loads a `.ply` or `.obj` file. Errors name the file and what is wrong, in one line
// (missing file, a PLY shorter than its header promises, Assimp's parse error, face indices
// out of range, non-finite coordinates or UVs, no triangles); Assimp logs nothing.
// - Geometry: coordinates as they are in the file (metres, the poses' world frame: no axis
//   conversion), with the local origin of SceneLoadOptions. Assimp reads coordinates as float
//   (Debian's build), so a map-scale file (~1e6 m) keeps float precision (~6 cm at 1e6 m)
//   even when the PLY stores doubles; they are widened to double before recentring.
// - Triangles in the file's order: Assimp's meshes (one per OBJ group or material run, in file
//   order) are concatenated and polygons are triangulated in place (aiProcess_Triangulate, no
//   step that reorders faces or welds vertices), so triangle indices match the file's faces
//   for a triangle-only file. Counter-clockwise = front, as written. Triangles with area below
//   min_triangle_area_m2 are dropped (counted in dropped_degenerate); point and line faces are
//   skipped (counted in skipped_primitives). Only vertices used by kept triangles are stored.
// - UVs: the first UV channel where a mesh has one (has_uv), flipped to glTF's convention:
//   v = 1 - v_file, since OBJ's and PLY's v = 0 is the bottom of the image and glTF's (and
//   Texture::rgba's row 0) the top. Vertex colours are accepted and ignored.
// - Materials: a default white one (index 0, "default"), plus one white material per file
//   material with a diffuse texture (OBJ `map_Kd`, PLY `comment TextureFile`), its image
//   decoded to RGBA8; a texture that cannot be read is a warning and its triangles use the
//   default material.
Status LoadMeshScene(const std::string& path, const SceneLoadOptions& options, Scene* scene);
// A plain binary PLY (little-endian, float x, y, z, triangles with 8-bit counts and 32-bit
// indices, no texture: what OpenMVS writes) is read without Assimp, into what Assimp reads of
// it. This reads every file through Assimp (tests compare the two).
Status LoadMeshSceneThroughAssimp(const std::string& path, const SceneLoadOptions& options,
                                  Scene* scene);

}  // namespace fresco
