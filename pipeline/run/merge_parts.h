// `fresco merge PART_DIR... --out DIR`: the parts that `fresco run --shard I/N` wrote (shard.h)
// joined into the outputs one `fresco run` writes: painted.gltf and its .bin as every part has
// them (the atlas is laid out once from the whole mesh), each atlas page (and each view layer's
// page) made of every shard's own charts with their padding (a part's page file holds only
// those: PaintSession::PaintedSceneOfOwnBuffers), and metrics.json with the run's
// figures joined (texels painted summed from the buffers' owners; wall time the slowest
// shard's; stage times per frame summed) and each shard's in "shards".
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace fresco {

struct MergeResult {
  int shards = 0;
  int textures = 0;        // PNG pages joined
  double cpu_seconds = 0;  // the shards' CPU time in all
  double largest_shard_seconds = 0, mean_shard_seconds = 0;  // their painting loops' wall time
};

// Checks the parts (each a shard of the same project, painted with the same settings and
// layout; every index of 0..N-1 once) and writes DIR's outputs all or nothing (metrics.json
// last). Bad parts: an error naming the part and what is wrong (bad input).
Status MergeParts(const std::vector<std::string>& part_dirs, const std::string& out_dir,
                  MergeResult* result);

}  // namespace fresco
