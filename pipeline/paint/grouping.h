// Base-buffer grouping (paper §3.6): neighbouring triangles with similar normals share one
// base texture buffer. Region growing over the mesh's edge adjacency from the largest
// unassigned triangle; a neighbour joins when its normal is within `angle_deg` of the
// seed's normal. The result is data: it can be stored in the project, edited (merge, split,
// move triangles, per-group texel size) and honoured by `fresco run`.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "pipeline/core/project.h"
#include "pipeline/core/scene.h"
#include "pipeline/core/status.h"

namespace fresco {

// A group: its triangles and an optional texel size of its own (> 0 overrides the
// session's). The same type as stored in the project file.
using BaseBufferGroup = GroupSpec;

struct Grouping {
  std::vector<BaseBufferGroup> groups;
  // (T) group of each triangle, -1 for triangles in no group (never painted).
  std::vector<int> group_of_triangle;

  void RebuildIndex(int num_triangles);
};

Grouping ComputeGrouping(const TriangleMesh& mesh, const MeshAdjacency& adjacency,
                         double angle_deg);

// The grouping a project asks for: `options.groups` when given (checked: triangles exist and
// are in one group at most; errors name "grouping.groups[i]"), else the automatic one (charts
// (charts.h) sized by `scale`; with min_chart_texels = 0 the paper's, ComputeGrouping); then
// the edits.
struct ChartScale;
Status MakeGrouping(const TriangleMesh& mesh, const GroupingOptions& options, Grouping* grouping);
Status MakeGrouping(const TriangleMesh& mesh, const GroupingOptions& options,
                    const ChartScale& scale, Grouping* grouping);

// Applies edits in order. Errors name the edit ("grouping.edits[2]: group 9 does not
// exist"). Ops: "merge" (groups -> first of them), "split" (triangles leave their group and
// form a new one), "move" (triangles -> target_group), "texel" (groups get texel_size_m).
Status ApplyGroupingEdits(const std::vector<GroupingEdit>& edits, int num_triangles,
                          Grouping* grouping);

// Per triangle: unit normal and area; and the triangles by decreasing area (ties by index:
// deterministic), the order region growing takes its seeds in.
struct TriangleFacts {
  std::vector<Eigen::Vector3d> normals;
  std::vector<double> areas;
  std::vector<int> by_decreasing_area;
};
TriangleFacts ComputeTriangleFacts(const TriangleMesh& mesh);

// Area-weighted mean unit normal of a group.
Eigen::Vector3d GroupNormal(const TriangleMesh& mesh, const BaseBufferGroup& group);

}  // namespace fresco
