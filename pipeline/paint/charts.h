// Charts: the automatic grouping for meshes from photogrammetry and scanning, whose normals
// are noisy at every triangle (the paper's neighbour-by-normal grouping, §3.6, degenerates to
// one buffer per triangle there). Three steps:
// 1. Region growing from the largest unassigned triangle over normals smoothed for it (three
//    rounds of averaging with the triangles around each vertex within 60 degrees: the noise
//    averages out, a box's edge stays sharp). A neighbour joins when its smoothed normal is
//    within `angle_deg` of the chart's mean smoothed normal (a cone that follows the chart)
//    and within the stretch bound (1 / cos <= `max_stretch`) of the seed's (so a slowly
//    curving surface cannot drift around), when the triangle itself, noise and all, faces
//    the chart's plane (within 84 degrees: no fold), and while the chart's area stays under
//    4 x `max_chart_texels` texels (a bigger buffer gets coarser texels).
// 2. Charts under `min_chart_texels` are merged, smallest first, into the neighbour they
//    share the most edges with, when every triangle of both faces the merged chart's plane
//    (within 84 degrees) and the small chart's smoothed normals stretch by at most
//    `max_stretch` on average (by area).
// 3. What is still small faces away from every chart around it (a fold of the fused surface,
//    a noise spike): its triangles go to shared charts, one per axis direction (the one each
//    triangle faces most, within 55 degrees) and cell of space as wide as the largest buffer.
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
// has moved to a buffer of its own, so this is finite (at most 10: BuildBaseBuffers moves
// out anything steeper).
ChartStretch MeasureBufferStretch(const TriangleMesh& mesh, const std::vector<BaseBuffer>& buffers);

}  // namespace fresco
