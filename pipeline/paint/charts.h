// Charts: the automatic grouping for meshes from photogrammetry and scanning, whose normals
// are noisy at every triangle (the paper's neighbour-by-normal grouping, §3.6, degenerates to
// one buffer per triangle there). Two steps:
// 1. Region growing from the largest unassigned triangle; a neighbour joins when its normal
//    is within `angle_deg` of the chart's area-weighted mean normal (a cone that follows the
//    chart, not the seed, so noise averages out), within the stretch bound of the seed's
//    normal (so a slowly curving surface cannot drift around), and while the chart's area
//    stays under 4 x `max_chart_texels` texels (a bigger buffer gets coarser texels).
// 2. Charts under `min_chart_texels` are merged, smallest first, into the neighbour they
//    share the most edges with, when the merged chart's plane sees the small chart's
//    triangles with an area-weighted mean texel stretch 1 / cos(angle) of at most
//    `max_stretch`, each of them within 84 degrees (no fold), and the larger chart's worst
//    triangle still within the bound. (Single noise spikes steeper than the bound so join
//    their neighbours: MeasureChartStretch reports the largest stretch as it is.)
// The chart count then follows the surface's shape, not its triangle count. Charts that
// would still fold in their plane are split when their buffers are built (base_buffer.h).
#pragma once

#include <vector>

#include "pipeline/core/project.h"
#include "pipeline/core/scene.h"
#include "pipeline/paint/base_buffer.h"
#include "pipeline/paint/grouping.h"

namespace fresco {

// Sizes in texels need the texel size; without it (texel_size_m = 0) no chart is merged and
// growth has no size limit.
struct ChartScale {
  double texel_size_m = 0.0;
  long long max_chart_texels = 0;  // 0: no limit
};

Grouping ComputeCharts(const TriangleMesh& mesh, const MeshAdjacency& adjacency,
                       const GroupingOptions& options, const ChartScale& scale);

// How much the charts' planes stretch their triangles' texels: 1 / cos(angle between the
// triangle's normal and its group's mean normal), the largest and the area-weighted mean
// over grouped triangles.
struct ChartStretch {
  double max = 1.0;
  double mean = 1.0;
};
ChartStretch MeasureChartStretch(const TriangleMesh& mesh, const Grouping& grouping);
// The same, each triangle against the plane its base buffer actually projects it onto (what
// `metrics.json` reports): after fold splits a triangle facing away from its chart's plane
// has moved to a buffer of its own, so this is finite (at most 1000: BuildBaseBuffers moves
// out anything steeper).
ChartStretch MeasureBufferStretch(const TriangleMesh& mesh, const std::vector<BaseBuffer>& buffers);

}  // namespace fresco
