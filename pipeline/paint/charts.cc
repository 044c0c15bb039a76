#include "pipeline/paint/charts.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <numeric>

namespace fresco {
namespace {

struct Chart {
  std::vector<int> triangles;
  Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();  // area-weighted
  double area = 0.0;
  int worst = -1;  // its triangle furthest from its mean normal
  bool alive = true;

  Eigen::Vector3d Normal() const {
    const double n = normal_sum.norm();
    return n > 0 ? Eigen::Vector3d(normal_sum / n) : Eigen::Vector3d::UnitZ();
  }
};

// A triangle merged into a chart must face its plane at least this much (cos 84 degrees):
// well away from edge-on, where its texels would fold or stretch without bound.
constexpr double kMinMergeCos = 0.1;
// A chart grown to the size limit still takes in its small neighbours up to this factor over
// the limit (its buffer's texels then get at most 5 % coarser).
constexpr double kMergeHeadroom = 1.1;

}  // namespace

Grouping ComputeCharts(const TriangleMesh& mesh, const MeshAdjacency& adjacency,
                       const GroupingOptions& options, const ChartScale& scale) {
  const int n = mesh.NumTriangles();
  const double cos_cone = std::cos(options.angle_deg * M_PI / 180.0);
  const double cos_stretch = 1.0 / options.max_stretch;
  const double texel_area = scale.texel_size_m * scale.texel_size_m;
  // Growth stops at 4x the largest buffer's texels: a bigger chart gets texels at most ~2x
  // coarser (base_buffer.h) before it is split, so a planar model's faces stay one chart
  // each (as in the paper) while a photogrammetry mesh's ground does not lose its detail.
  const double max_area = texel_area > 0 && scale.max_chart_texels > 0
                              ? 4.0 * static_cast<double>(scale.max_chart_texels) * texel_area
                              : std::numeric_limits<double>::infinity();
  const TriangleFacts facts = ComputeTriangleFacts(mesh);
  const std::vector<Eigen::Vector3d>& normals = facts.normals;
  const std::vector<double>& areas = facts.areas;
  const std::vector<int>& order = facts.by_decreasing_area;

  // 1. Region growing, in rounds: a chart's mean normal moves as it grows, so triangles that
  // end up beyond the stretch bound of the final mean leave it and seed charts of their own
  // in the next round (the last round keeps what it grows).
  std::vector<Chart> charts;
  std::vector<int> chart_of(n, -1);
  std::deque<int> queue;
  constexpr int kRounds = 4;
  for (int round = 0; round < kRounds; ++round) {
    bool evicted = false;
    for (int seed : order) {
      if (chart_of[seed] >= 0 || areas[seed] <= 0.0) continue;
      const int c = static_cast<int>(charts.size());
      charts.emplace_back();
      Chart& chart = charts.back();
      const Eigen::Vector3d seed_normal = normals[seed];
      chart_of[seed] = c;
      queue.assign(1, seed);
      while (!queue.empty()) {
        const int t = queue.front();
        queue.pop_front();
        chart.triangles.push_back(t);
        chart.normal_sum += normals[t] * areas[t];
        chart.area += areas[t];
        const Eigen::Vector3d mean = chart.Normal();
        for (int nb : adjacency.Neighbours(t)) {
          if (chart_of[nb] >= 0 || areas[nb] <= 0.0) continue;
          if (normals[nb].dot(mean) < cos_cone || normals[nb].dot(seed_normal) < cos_stretch)
            continue;
          if (chart.area + areas[nb] > max_area) continue;
          chart_of[nb] = c;
          queue.push_back(nb);
        }
      }
      if (round + 1 < kRounds) {
        const Eigen::Vector3d mean = chart.Normal();
        auto beyond = [&](int t) { return normals[t].dot(mean) < cos_stretch; };
        for (int t : chart.triangles) {
          if (!beyond(t)) continue;
          chart_of[t] = -1;
          chart.normal_sum -= normals[t] * areas[t];
          chart.area -= areas[t];
          evicted = true;
        }
        chart.triangles.erase(std::remove_if(chart.triangles.begin(), chart.triangles.end(), beyond),
                              chart.triangles.end());
      }
      if (chart.triangles.empty()) {  // cannot happen (the seed is within the bound), but
        chart.alive = false;           // an empty chart must not be used
        continue;
      }
      const Eigen::Vector3d mean = chart.Normal();
      chart.worst = *std::min_element(
          chart.triangles.begin(), chart.triangles.end(),
          [&](int a, int b) { return normals[a].dot(mean) < normals[b].dot(mean); });
    }
    if (!evicted) break;
  }

  // 2. Small charts into a neighbour, in passes (smallest first in each): a small chart that
  // took in a smaller one may be merged itself in the next pass.
  const bool merging = texel_area > 0 && options.min_chart_texels > 0;
  bool merged_any = merging;
  for (int pass = 0; pass < 8 && merged_any; ++pass) {
    merged_any = false;
    const double min_area = options.min_chart_texels * texel_area;
    std::vector<int> by_area;
    for (int c = 0; c < static_cast<int>(charts.size()); ++c)
      if (charts[c].alive && charts[c].area < min_area) by_area.push_back(c);
    std::stable_sort(by_area.begin(), by_area.end(),
                     [&](int a, int b) { return charts[a].area < charts[b].area; });
    for (int c : by_area) {
      Chart& small = charts[c];
      if (!small.alive || small.area >= min_area) continue;
      std::map<int, int> shared;  // neighbouring chart -> edges shared
      for (int t : small.triangles)
        for (int nb : adjacency.Neighbours(t))
          if (chart_of[nb] >= 0 && chart_of[nb] != c) ++shared[chart_of[nb]];
      std::vector<std::pair<int, int>> candidates(shared.begin(), shared.end());
      std::stable_sort(candidates.begin(), candidates.end(),
                       [](const auto& a, const auto& b) { return a.second > b.second; });
      for (const auto& [d, edges] : candidates) {
        Chart& big = charts[d];
        if (small.area + big.area > kMergeHeadroom * max_area) continue;
        const Eigen::Vector3d merged = (small.normal_sum + big.normal_sum).normalized();
        if (!std::isfinite(merged.x())) continue;
        // The larger chart keeps its worst triangle within the bound; the small chart's
        // triangles must face the plane (no fold: at most kMaxMergeAngle away) and stretch
        // within the bound on average (by area): a noise spike of one triangle steeper than
        // the bound goes with its neighbours instead of staying a chart of its own.
        bool ok = normals[big.worst].dot(merged) >= std::min(cos_stretch, kMinMergeCos);
        int worst = big.worst;
        double stretch_area = 0.0;
        for (int t : small.triangles) {
          const double c = normals[t].dot(merged);
          if (c < kMinMergeCos) {
            ok = false;
            break;
          }
          stretch_area += areas[t] / c;
          if (c < normals[worst].dot(merged)) worst = t;
        }
        if (!ok || stretch_area > options.max_stretch * small.area) continue;
        for (int t : small.triangles) chart_of[t] = d;
        big.triangles.insert(big.triangles.end(), small.triangles.begin(), small.triangles.end());
        big.normal_sum += small.normal_sum;
        big.area += small.area;
        big.worst = worst;
        small.alive = false;
        small.triangles.clear();
        merged_any = true;
        break;
      }
    }
  }

  Grouping grouping;
  for (Chart& chart : charts) {
    if (!chart.alive) continue;
    std::sort(chart.triangles.begin(), chart.triangles.end());
    BaseBufferGroup group;
    group.triangles = std::move(chart.triangles);
    grouping.groups.push_back(std::move(group));
  }
  grouping.RebuildIndex(n);
  return grouping;
}

namespace {

// Area-weighted stretch 1/cos of triangles against the plane normals given per group.
template <class Groups, class NormalOf, class TrianglesOf>
ChartStretch StretchOf(const TriangleMesh& mesh, const Groups& groups, const NormalOf& normal_of,
                       const TrianglesOf& triangles_of) {
  ChartStretch s;
  double weighted = 0.0, area = 0.0;
  for (const auto& group : groups) {
    const Eigen::Vector3d normal = normal_of(group);
    for (int t : triangles_of(group)) {
      const double c = mesh.Normal(t).dot(normal);
      const double stretch = c > 1e-6 ? 1.0 / c : std::numeric_limits<double>::infinity();
      const double a = mesh.Area(t);
      s.max = std::max(s.max, stretch);
      weighted += std::min(stretch, 1e6) * a;
      area += a;
    }
  }
  if (area > 0) s.mean = weighted / area;
  return s;
}

}  // namespace

ChartStretch MeasureChartStretch(const TriangleMesh& mesh, const Grouping& grouping) {
  return StretchOf(
      mesh, grouping.groups, [&](const BaseBufferGroup& g) { return GroupNormal(mesh, g); },
      [](const BaseBufferGroup& g) -> const std::vector<int>& { return g.triangles; });
}

ChartStretch MeasureBufferStretch(const TriangleMesh& mesh, const std::vector<BaseBuffer>& buffers) {
  return StretchOf(
      mesh, buffers, [](const BaseBuffer& b) { return b.normal; },
      [](const BaseBuffer& b) -> const std::vector<int>& { return b.triangles; });
}

}  // namespace fresco
