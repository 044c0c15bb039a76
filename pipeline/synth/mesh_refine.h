// Makes a scene's mesh look like what photogrammetry or scanning produces: every triangle
// subdivided into n x n smaller ones (UVs and materials follow), then every vertex moved by
// Gaussian noise (each coordinate, sigma `noise_m`), so that normals are noisy at every
// triangle. The noise is a function of the vertex's position (and the seed): vertices that
// several triangles share move together, and the mesh stays closed where it was.
// `fresco synth` uses it ("mesh": {"subdivide": N, "noise_m": S}) to make large, noisy meshes
// to paint (e.g. the room with subdivide 290: 1.0 M triangles).
#pragma once

#include "pipeline/core/scene.h"
#include "pipeline/core/status.h"

namespace fresco {

struct MeshRefineOptions {
  int subdivide = 1;     // 1 = unchanged
  double noise_m = 0.0;  // 0 = no noise
  unsigned seed = 1;
};

// Errors: subdivide < 1 or too many triangles (over 2^28), noise < 0.
Status RefineMesh(const MeshRefineOptions& options, Scene* scene);

}  // namespace fresco
