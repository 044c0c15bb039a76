#include "pipeline/paint/grouping.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <numeric>

#include "pipeline/paint/charts.h"

namespace fresco {

void Grouping::RebuildIndex(int num_triangles) {
  group_of_triangle.assign(num_triangles, -1);
  for (int g = 0; g < static_cast<int>(groups.size()); ++g)
    for (int t : groups[g].triangles) group_of_triangle[t] = g;
}

Grouping ComputeGrouping(const TriangleMesh& mesh, const MeshAdjacency& adjacency,
                         double angle_deg) {
  const int n = mesh.NumTriangles();
  const double cos_limit = std::cos(angle_deg * M_PI / 180.0);
  const TriangleFacts facts = ComputeTriangleFacts(mesh);
  const std::vector<Eigen::Vector3d>& normals = facts.normals;
  const std::vector<double>& areas = facts.areas;
  const std::vector<int>& order = facts.by_decreasing_area;

  Grouping grouping;
  grouping.group_of_triangle.assign(n, -1);
  std::deque<int> queue;
  for (int seed : order) {
    if (grouping.group_of_triangle[seed] >= 0 || areas[seed] <= 0.0) continue;
    const int g = static_cast<int>(grouping.groups.size());
    grouping.groups.emplace_back();
    BaseBufferGroup& group = grouping.groups.back();
    const Eigen::Vector3d seed_normal = normals[seed];
    grouping.group_of_triangle[seed] = g;
    queue.assign(1, seed);
    while (!queue.empty()) {
      const int t = queue.front();
      queue.pop_front();
      group.triangles.push_back(t);
      for (int nb : adjacency.Neighbours(t)) {
        if (grouping.group_of_triangle[nb] >= 0 || areas[nb] <= 0.0) continue;
        if (normals[nb].dot(seed_normal) < cos_limit) continue;
        grouping.group_of_triangle[nb] = g;
        queue.push_back(nb);
      }
    }
    std::sort(group.triangles.begin(), group.triangles.end());
  }
  return grouping;
}

static void RemoveEmptyGroups(Grouping* grouping, int num_triangles) {
  auto& groups = grouping->groups;
  groups.erase(std::remove_if(groups.begin(), groups.end(),
                              [](const BaseBufferGroup& g) { return g.triangles.empty(); }),
               groups.end());
  grouping->RebuildIndex(num_triangles);
}

static void TakeTriangles(const std::vector<int>& triangles, int num_triangles,
                          Grouping* grouping) {
  std::vector<bool> taken(num_triangles, false);
  for (int t : triangles) taken[t] = true;
  for (auto& group : grouping->groups) {
    auto& tris = group.triangles;
    tris.erase(std::remove_if(tris.begin(), tris.end(), [&](int t) { return taken[t]; }),
               tris.end());
  }
}

Status ApplyGroupingEdits(const std::vector<GroupingEdit>& edits, int num_triangles,
                          Grouping* grouping) {
  for (size_t i = 0; i < edits.size(); ++i) {
    const GroupingEdit& e = edits[i];
    const std::string where = "grouping.edits[" + std::to_string(i) + "]";
    const int num_groups = static_cast<int>(grouping->groups.size());
    for (int g : e.groups)
      if (g < 0 || g >= num_groups)
        return Status::Error(where + ": group " + std::to_string(g) + " does not exist (" +
                             std::to_string(num_groups) + " groups)");
    for (int t : e.triangles)
      if (t < 0 || t >= num_triangles)
        return Status::Error(where + ": triangle " + std::to_string(t) + " does not exist (" +
                             std::to_string(num_triangles) + " triangles)");
    if (e.op == "merge") {
      if (e.groups.size() < 2) return Status::Error(where + ": merge needs 2 or more groups");
      auto& into = grouping->groups[e.groups[0]].triangles;
      for (size_t k = 1; k < e.groups.size(); ++k) {
        auto& from = grouping->groups[e.groups[k]].triangles;
        if (e.groups[k] == e.groups[0]) continue;
        into.insert(into.end(), from.begin(), from.end());
        from.clear();
      }
      std::sort(into.begin(), into.end());
    } else if (e.op == "split") {
      if (e.triangles.empty()) return Status::Error(where + ": split needs triangles");
      TakeTriangles(e.triangles, num_triangles, grouping);
      BaseBufferGroup g;
      g.triangles = e.triangles;
      std::sort(g.triangles.begin(), g.triangles.end());
      grouping->groups.push_back(g);
    } else if (e.op == "move") {
      if (e.target_group < 0 || e.target_group >= num_groups)
        return Status::Error(where + ": target_group " + std::to_string(e.target_group) +
                             " does not exist");
      TakeTriangles(e.triangles, num_triangles, grouping);
      auto& into = grouping->groups[e.target_group].triangles;
      into.insert(into.end(), e.triangles.begin(), e.triangles.end());
      std::sort(into.begin(), into.end());
    } else if (e.op == "texel") {
      if (!(e.texel_size_m > 0.0))
        return Status::Error(where + ": texel_size_m must be > 0");
      for (int g : e.groups) grouping->groups[g].texel_size_m = e.texel_size_m;
    } else {
      return Status::Error(where + ": op: unknown '" + e.op +
                           "' (expected merge, split, move or texel)");
    }
    RemoveEmptyGroups(grouping, num_triangles);
  }
  grouping->RebuildIndex(num_triangles);
  return Status::Ok();
}

Status MakeGrouping(const TriangleMesh& mesh, const GroupingOptions& options, Grouping* grouping) {
  return MakeGrouping(mesh, options, ChartScale(), grouping);
}

Status MakeGrouping(const TriangleMesh& mesh, const GroupingOptions& options,
                    const ChartScale& scale, Grouping* grouping) {
  const int num_triangles = mesh.NumTriangles();
  if (options.groups.empty()) {
    const MeshAdjacency adjacency = ComputeAdjacency(mesh);
    *grouping = options.min_chart_texels > 0
                    ? ComputeCharts(mesh, adjacency, options, scale)
                    : ComputeGrouping(mesh, adjacency, options.angle_deg);
  } else {
    grouping->groups.clear();
    std::vector<int> owner(num_triangles, -1);
    for (size_t g = 0; g < options.groups.size(); ++g) {
      const std::string where = "grouping.groups[" + std::to_string(g) + "]";
      for (int t : options.groups[g].triangles) {
        if (t < 0 || t >= num_triangles)
          return Status::Error(where + ": triangle " + std::to_string(t) + " does not exist (" +
                               std::to_string(num_triangles) + " triangles)");
        if (owner[t] >= 0)
          return Status::Error(where + ": triangle " + std::to_string(t) +
                               " is also in grouping.groups[" + std::to_string(owner[t]) + "]");
        owner[t] = static_cast<int>(g);
      }
      grouping->groups.push_back(options.groups[g]);
    }
    RemoveEmptyGroups(grouping, num_triangles);
  }
  return ApplyGroupingEdits(options.edits, num_triangles, grouping);
}

TriangleFacts ComputeTriangleFacts(const TriangleMesh& mesh) {
  const int n = mesh.NumTriangles();
  TriangleFacts f;
  f.normals.resize(n);
  f.areas.resize(n);
  for (int t = 0; t < n; ++t) {
    f.normals[t] = mesh.Normal(t);
    f.areas[t] = mesh.Area(t);
  }
  f.by_decreasing_area.resize(n);
  std::iota(f.by_decreasing_area.begin(), f.by_decreasing_area.end(), 0);
  std::stable_sort(f.by_decreasing_area.begin(), f.by_decreasing_area.end(),
                   [&](int a, int b) { return f.areas[a] > f.areas[b]; });
  return f;
}

Eigen::Vector3d GroupNormal(const TriangleMesh& mesh, const BaseBufferGroup& group) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int t : group.triangles) sum += mesh.Normal(t) * mesh.Area(t);
  const double norm = sum.norm();
  return norm > 0 ? Eigen::Vector3d(sum / norm) : Eigen::Vector3d::UnitZ();
}

}  // namespace fresco
