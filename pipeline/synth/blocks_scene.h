// A built-in scene for structure from motion (`builtin:blocks`): a cluster of boxes of
// random sizes standing on a ground plane, every face with its own procedural feature
// texture (no two alike, nothing repeats), so that COLMAP reconstructs it unambiguously
// from an orbit around it. Deterministic for a seed. World frame = glTF frame (+Y up,
// metres); the ground is y = 0, centred on the origin.
#pragma once

#include "pipeline/core/scene.h"
#include "pipeline/core/status.h"

namespace fresco {

struct BlocksOptions {
  double ground_m = 6.0;    // the ground is a ground_m x ground_m square
  int blocks = 7;           // boxes standing on it
  double area_m = 3.0;      // ...within an area_m x area_m square in the middle
  double min_size_m = 0.4;  // box width and depth drawn in [min_size_m, max_size_m]
  double max_size_m = 1.1;
  double max_height_m = 1.6;  // box heights drawn in [min_size_m, max_height_m]
  int texels_per_m = 160;     // texture resolution on every face
  unsigned seed = 1;

  Status Check() const;  // message names the field
};

// Ground (one quad) and `blocks` boxes placed without overlap (as many as fit after a
// bounded number of tries), each face (four sides and the top) its own texture.
Status MakeBlocksScene(const BlocksOptions& options, Scene* scene);

}  // namespace fresco
