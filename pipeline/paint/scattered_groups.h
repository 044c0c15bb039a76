// Groups whose triangles lie scattered over their plane: the pieces a fold split moves out
// together, or the charts' leftovers pooled by axis and cell (charts.h). A buffer's per-texel
// arrays cover its whole rectangle, so such a group's buffer is mostly texels no triangle
// owns (on a fused room mesh, 207 buffers held 64 % of the rectangles' texels and 5 % of the
// surface's). SplitScatteredGroup cuts them into compact pieces first.
#pragma once

#include <vector>

#include "pipeline/core/scene.h"
#include "pipeline/paint/grouping.h"

namespace fresco {

// `group` cut in two, recursively, while its triangles cover under kScatteredFill of its
// rectangle (its buffer's plane at `texel_size_m`, `gutter_texels` around) and a straight cut
// between them (across either axis, between their centres in order) saves
// kScatteredCutSavesTexels or more of it: the cut saving most each time. Each piece keeps
// the group's texel size and its triangles in their order; a compact group, or one scattered
// evenly over its rectangle (a fused surface's folds), comes back whole.
std::vector<BaseBufferGroup> SplitScatteredGroup(const TriangleMesh& mesh,
                                                 const BaseBufferGroup& group, double texel_size_m,
                                                 int gutter_texels);

// A buffer's own cost (its atlas padding, its set-up per frame) in texels, about.
inline constexpr double kScatteredCutSavesTexels = 64 * 64;
inline constexpr double kScatteredFill = 0.25;

}  // namespace fresco
