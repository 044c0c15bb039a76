#include "pipeline/paint/charts.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <numeric>

namespace fresco {
namespace {

Eigen::Vector3d UnitOr(const Eigen::Vector3d& sum, const Eigen::Vector3d& fallback) {
  const double n = sum.norm();
  return n > 0 ? Eigen::Vector3d(sum / n) : fallback;
}

struct Chart {
  std::vector<int> triangles;
  Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();  // area-weighted: the buffer's plane
  Eigen::Vector3d smooth_sum = Eigen::Vector3d::Zero();  // the same of smoothed normals
  double area = 0.0;
  int worst = -1;  // its triangle furthest from its mean normal
  bool alive = true;

  Eigen::Vector3d Normal() const { return UnitOr(normal_sum, Eigen::Vector3d::UnitZ()); }
  Eigen::Vector3d SmoothNormal() const { return UnitOr(smooth_sum, Normal()); }
};

// A chart grown to the size limit still takes in its small neighbours up to this factor over
// the limit (its buffer's texels then get at most 5 % coarser).
constexpr double kMergeHeadroom = 1.1;
// Normal smoothing for growth: rounds of averaging each triangle's normal with those of the
// triangles around its vertices within 60 degrees of it (wider than the noise of a fused
// mesh, narrower than a box's edge, which stays sharp).
constexpr int kSmoothRounds = 3;
constexpr float kSmoothCos = 0.5f;

// (T) unit normals smoothed over the triangles sharing a vertex (welded), by area.
std::vector<Eigen::Vector3f> SmoothNormals(const TriangleMesh& mesh, const MeshAdjacency& adjacency,
                                           const TriangleFacts& facts) {
  const int n = mesh.NumTriangles();
  const std::vector<int>& weld = adjacency.welded_vertex;
  auto vertex_of = [&](int t, int k) {
    const int v = mesh.triangles[t][k];
    return v < static_cast<int>(weld.size()) ? weld[v] : v;
  };
  // Triangles around each vertex: around[start[v] .. start[v + 1]).
  std::vector<int64_t> start(mesh.vertices.size() + 1, 0);
  for (int t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k) ++start[vertex_of(t, k) + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<int> around(start.back());
  {
    std::vector<int64_t> fill(start.begin(), start.end() - 1);
    for (int t = 0; t < n; ++t)
      for (int k = 0; k < 3; ++k) around[fill[vertex_of(t, k)]++] = t;
  }
  std::vector<Eigen::Vector3f> smooth(n), next(n);
  for (int t = 0; t < n; ++t) smooth[t] = facts.normals[t].cast<float>();
  for (int round = 0; round < kSmoothRounds; ++round) {
    for (int t = 0; t < n; ++t) {
      Eigen::Vector3f sum = smooth[t] * static_cast<float>(facts.areas[t]);
      for (int k = 0; k < 3; ++k) {
        const int v = vertex_of(t, k);
        for (int64_t i = start[v]; i < start[v + 1]; ++i) {
          const int u = around[i];
          if (u != t && smooth[u].dot(smooth[t]) >= kSmoothCos)
            sum += smooth[u] * static_cast<float>(facts.areas[u]);
        }
      }
      const float norm = sum.norm();
      next[t] = norm > 0 ? Eigen::Vector3f(sum / norm) : smooth[t];
    }
    smooth.swap(next);
  }
  return smooth;
}

void AddTriangle(int t, const TriangleFacts& facts, const std::vector<Eigen::Vector3f>& smooth,
                 Chart* chart) {
  chart->triangles.push_back(t);
  chart->normal_sum += facts.normals[t] * facts.areas[t];
  chart->smooth_sum += smooth[t].cast<double>() * facts.areas[t];
  chart->area += facts.areas[t];
}

// Builds a mesh's charts in three steps: region growing, small charts merged into a
// neighbour, and what is still small pooled by axis and cell.
class ChartBuilder {
 public:
  ChartBuilder(const TriangleMesh& mesh, const MeshAdjacency& adjacency,
               const GroupingOptions& options, const ChartScale& scale)
      : mesh_(mesh),
        adjacency_(adjacency),
        options_(options),
        scale_(scale),
        cos_cone_(std::cos(options.angle_deg * M_PI / 180.0)),
        cos_stretch_(1.0 / options.max_stretch),
        texel_area_(scale.texel_size_m * scale.texel_size_m),
        // Growth stops at 4x the largest buffer's texels: a bigger chart gets texels at most
        // ~2x coarser (base_buffer.h) before it is split, so a planar model's faces stay one
        // chart each (as in the paper) while a photogrammetry mesh's ground does not lose
        // its detail.
        max_area_(texel_area_ > 0 && scale.max_chart_texels > 0
                      ? 4.0 * static_cast<double>(scale.max_chart_texels) * texel_area_
                      : std::numeric_limits<double>::infinity()),
        merging_(texel_area_ > 0 && options.min_chart_texels > 0),
        min_area_(options.min_chart_texels * texel_area_),
        facts_(ComputeTriangleFacts(mesh)),
        smooth_(SmoothNormals(mesh, adjacency, facts_)),
        chart_of_(mesh.NumTriangles(), -1) {}

  // 1. Region growing, in rounds: a chart's mean normals move as it grows, so triangles that
  // end up outside its bounds leave it and seed charts of their own in the next round; what
  // is left after the last round becomes charts of one triangle (merged in step 2).
  void GrowRegions() {
    const std::vector<double>& areas = facts_.areas;
    const std::vector<int>& order = facts_.by_decreasing_area;
    std::deque<int> queue;
    constexpr int kRounds = 4;
    for (int round = 0; round < kRounds; ++round) {
      bool evicted = false;
      for (int seed : order) {
        if (chart_of_[seed] >= 0 || areas[seed] <= 0.0) continue;
        GrowChart(seed, &queue);
        if (Evict(&charts_.back())) evicted = true;
      }
      if (!evicted) break;
    }
    for (int t : order) {
      if (chart_of_[t] >= 0 || areas[t] <= 0.0) continue;
      chart_of_[t] = static_cast<int>(charts_.size());
      charts_.emplace_back();
      AddTriangle(t, facts_, smooth_, &charts_.back());
    }
    for (Chart& chart : charts_) {
      if (!chart.alive) continue;
      const Eigen::Vector3d mean = chart.Normal();
      chart.worst = *std::min_element(
          chart.triangles.begin(), chart.triangles.end(),
          [&](int a, int b) { return facts_.normals[a].dot(mean) < facts_.normals[b].dot(mean); });
    }
  }

  // 2. Small charts into a neighbour, in passes (smallest first in each): a small chart that
  // took in a smaller one may be merged itself in the next pass.
  void MergeSmallCharts() {
    bool merged_any = merging_;
    for (int pass = 0; pass < 8 && merged_any; ++pass) {
      merged_any = false;
      std::vector<int> by_area;
      for (int c = 0; c < static_cast<int>(charts_.size()); ++c)
        if (charts_[c].alive && charts_[c].area < min_area_) by_area.push_back(c);
      std::stable_sort(by_area.begin(), by_area.end(),
                       [&](int a, int b) { return charts_[a].area < charts_[b].area; });
      for (int c : by_area) {
        const Chart& small = charts_[c];
        if (!small.alive || small.area >= min_area_) continue;
        if (MergeIntoNeighbour(c)) merged_any = true;
      }
    }
  }

  // 3. What is still small faces away from every chart around it (a fold of the noise, a
  // spike): triangle by triangle into shared charts, one per axis direction (+-x, +-y, +-z:
  // the one the triangle faces most, within 55 degrees) and cell of space (as wide as the
  // largest buffer), instead of a chart and a buffer each.
  void PoolLeftovers() {
    if (!merging_) return;
    const double cell_m =
        scale_.max_chart_texels > 0
            ? std::sqrt(static_cast<double>(scale_.max_chart_texels)) * scale_.texel_size_m
            : std::numeric_limits<double>::infinity();
    std::map<std::array<int64_t, 4>, int> shared_chart;  // (axis, cell) -> chart
    const int num_charts = static_cast<int>(charts_.size());
    for (int c = 0; c < num_charts; ++c) {
      if (!charts_[c].alive || charts_[c].area >= min_area_) continue;
      std::vector<int> triangles = std::move(charts_[c].triangles);
      charts_[c].alive = false;
      for (int t : triangles) {
        auto [it, added] =
            shared_chart.emplace(PoolKey(t, cell_m), static_cast<int>(charts_.size()));
        if (added) charts_.emplace_back();
        chart_of_[t] = it->second;
        AddTriangle(t, facts_, smooth_, &charts_[it->second]);
      }
    }
  }

  // The live charts as groups, each with its triangles in increasing order.
  Grouping TakeGrouping() {
    Grouping grouping;
    for (Chart& chart : charts_) {
      if (!chart.alive) continue;
      std::sort(chart.triangles.begin(), chart.triangles.end());
      BaseBufferGroup group;
      group.triangles = std::move(chart.triangles);
      grouping.groups.push_back(std::move(group));
    }
    grouping.RebuildIndex(mesh_.NumTriangles());
    return grouping;
  }

 private:
  double SmoothDot(int t, const Eigen::Vector3d& v) const {
    return smooth_[t].cast<double>().dot(v);
  }

  // Grows a new chart from `seed` over its neighbours, breadth first (`queue`: scratch).
  void GrowChart(int seed, std::deque<int>* queue) {
    const std::vector<Eigen::Vector3d>& normals = facts_.normals;
    const std::vector<double>& areas = facts_.areas;
    const int c = static_cast<int>(charts_.size());
    charts_.emplace_back();
    Chart& chart = charts_.back();
    const Eigen::Vector3d seed_smooth = smooth_[seed].cast<double>();
    chart_of_[seed] = c;
    queue->assign(1, seed);
    while (!queue->empty()) {
      const int t = queue->front();
      queue->pop_front();
      AddTriangle(t, facts_, smooth_, &chart);
      const Eigen::Vector3d mean = chart.Normal(), cone = chart.SmoothNormal();
      for (int nb : adjacency_.Neighbours(t)) {
        if (chart_of_[nb] >= 0 || areas[nb] <= 0.0) continue;
        // The surface (smoothed) stays within the cone and the stretch bound of the seed;
        // the triangle itself (noise and all) faces the plane: no fold.
        if (SmoothDot(nb, cone) < cos_cone_ || SmoothDot(nb, seed_smooth) < cos_stretch_ ||
            normals[nb].dot(mean) < kMinPlaneCos)
          continue;
        if (chart.area + areas[nb] > max_area_) continue;
        chart_of_[nb] = c;
        queue->push_back(nb);
      }
    }
  }

  // Takes out of a grown chart the triangles beyond its final bounds; returns whether any
  // left it.
  bool Evict(Chart* chart) {
    const std::vector<Eigen::Vector3d>& normals = facts_.normals;
    const std::vector<double>& areas = facts_.areas;
    bool evicted = false;
    const Eigen::Vector3d mean = chart->Normal(), cone = chart->SmoothNormal();
    auto beyond = [&](int t) {
      return normals[t].dot(mean) < kMinPlaneCos || SmoothDot(t, cone) < cos_stretch_;
    };
    for (int t : chart->triangles) {
      if (!beyond(t)) continue;
      chart_of_[t] = -1;
      chart->normal_sum -= normals[t] * areas[t];
      chart->smooth_sum -= smooth_[t].cast<double>() * areas[t];
      chart->area -= areas[t];
      evicted = true;
    }
    chart->triangles.erase(std::remove_if(chart->triangles.begin(), chart->triangles.end(), beyond),
                           chart->triangles.end());
    if (chart->triangles.empty()) chart->alive = false;  // its seed faces away from what it grew
    return evicted;
  }

  // Whether the small chart may join `big`: every triangle faces the merged plane (no fold:
  // at most 84 degrees away, the larger chart's worst one too), and the small chart's
  // surface (smoothed normals) stretches within the bound on average (by area). Sets
  // `worst` to the joined chart's triangle furthest from the merged plane.
  bool MayMerge(const Chart& small, const Chart& big, int* worst) const {
    const std::vector<Eigen::Vector3d>& normals = facts_.normals;
    if (small.area + big.area > kMergeHeadroom * max_area_) return false;
    const Eigen::Vector3d merged = (small.normal_sum + big.normal_sum).normalized();
    if (!std::isfinite(merged.x())) return false;
    bool ok = normals[big.worst].dot(merged) >= std::min(cos_stretch_, kMinPlaneCos);
    *worst = big.worst;
    double stretch_area = 0.0;
    for (int t : small.triangles) {
      const double c = normals[t].dot(merged);
      if (c < kMinPlaneCos) {
        ok = false;
        break;
      }
      stretch_area += facts_.areas[t] / std::max(SmoothDot(t, merged), kMinPlaneCos);
      if (c < normals[*worst].dot(merged)) *worst = t;
    }
    return ok && stretch_area <= options_.max_stretch * small.area;
  }

  // Merges small chart c into the neighbour it shares most edges with that may take it;
  // returns whether one did.
  bool MergeIntoNeighbour(int c) {
    Chart& small = charts_[c];
    std::map<int, int> shared;  // neighbouring chart -> edges shared
    for (int t : small.triangles)
      for (int nb : adjacency_.Neighbours(t))
        if (chart_of_[nb] >= 0 && chart_of_[nb] != c) ++shared[chart_of_[nb]];
    std::vector<std::pair<int, int>> candidates(shared.begin(), shared.end());
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const auto& a, const auto& b) { return a.second > b.second; });
    for (const auto& [d, edges] : candidates) {
      Chart& big = charts_[d];
      int worst = -1;
      if (!MayMerge(small, big, &worst)) continue;
      for (int t : small.triangles) chart_of_[t] = d;
      big.triangles.insert(big.triangles.end(), small.triangles.begin(), small.triangles.end());
      big.normal_sum += small.normal_sum;
      big.smooth_sum += small.smooth_sum;
      big.area += small.area;
      big.worst = worst;
      small.alive = false;
      small.triangles.clear();
      return true;
    }
    return false;
  }

  // The shared chart a leftover triangle joins: the axis direction it faces most and its
  // centre's cell (none when cells are unbounded).
  std::array<int64_t, 4> PoolKey(int t, double cell_m) const {
    const Eigen::Vector3d& normal = facts_.normals[t];
    int axis = 0;
    for (int a = 1; a < 6; ++a)
      if ((a % 2 ? -1 : 1) * normal[a / 2] > (axis % 2 ? -1 : 1) * normal[axis / 2]) axis = a;
    const Eigen::Vector3d centre =
        (mesh_.Corner(t, 0) + mesh_.Corner(t, 1) + mesh_.Corner(t, 2)) / 3.0;
    std::array<int64_t, 4> key{axis, 0, 0, 0};
    if (std::isfinite(cell_m))
      for (int k = 0; k < 3; ++k) key[k + 1] = static_cast<int64_t>(std::floor(centre[k] / cell_m));
    return key;
  }

  const TriangleMesh& mesh_;
  const MeshAdjacency& adjacency_;
  const GroupingOptions& options_;
  const ChartScale& scale_;
  const double cos_cone_;
  const double cos_stretch_;
  const double texel_area_;
  const double max_area_;
  const bool merging_;
  const double min_area_;
  const TriangleFacts facts_;
  const std::vector<Eigen::Vector3f> smooth_;
  std::vector<Chart> charts_;
  std::vector<int> chart_of_;
};

}  // namespace

Grouping ComputeCharts(const TriangleMesh& mesh, const MeshAdjacency& adjacency,
                       const GroupingOptions& options, const ChartScale& scale) {
  ChartBuilder builder(mesh, adjacency, options, scale);
  builder.GrowRegions();
  builder.MergeSmallCharts();
  builder.PoolLeftovers();
  return builder.TakeGrouping();
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

ChartStretch MeasureBufferStretch(const TriangleMesh& mesh,
                                  const std::vector<BaseBuffer>& buffers) {
  return StretchOf(
      mesh, buffers, [](const BaseBuffer& b) { return b.normal; },
      [](const BaseBuffer& b) -> const std::vector<int>& { return b.triangles; });
}

}  // namespace fresco
