// TriangleMesh geometry helpers, scene bounds and edge adjacency (with vertex welding).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <tuple>

#include <Eigen/Geometry>

#include "pipeline/core/scene.h"

namespace fresco {

Eigen::Vector3d TriangleMesh::Normal(int tri) const {
  const Eigen::Vector3d a = Corner(tri, 0);
  const Eigen::Vector3d n = (Corner(tri, 1) - a).cross(Corner(tri, 2) - a);
  const double length = n.norm();
  if (!(length > 0.0) || !std::isfinite(length)) return Eigen::Vector3d::Zero();
  return n / length;
}

double TriangleMesh::Area(int tri) const {
  const Eigen::Vector3d a = Corner(tri, 0);
  return 0.5 * (Corner(tri, 1) - a).cross(Corner(tri, 2) - a).norm();
}

void Scene::Bounds(Eigen::Vector3d* min_corner, Eigen::Vector3d* max_corner) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(kInf);
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-kInf);
  for (const Eigen::Vector3d& v : mesh.vertices) {
    if (!v.allFinite()) continue;
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  if (!(lo.x() <= hi.x())) {  // no (finite) vertices
    lo.setZero();
    hi.setZero();
  }
  if (min_corner) *min_corner = lo;
  if (max_corner) *max_corner = hi;
}

namespace {

// Union-find over vertex indices; the root of a set is its smallest index.
class DisjointSets {
 public:
  explicit DisjointSets(int n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  int Find(int i) {
    while (parent_[i] != i) {
      parent_[i] = parent_[parent_[i]];
      i = parent_[i];
    }
    return i;
  }
  void Union(int a, int b) {
    a = Find(a);
    b = Find(b);
    if (a == b) return;
    if (a < b) std::swap(a, b);
    parent_[a] = b;
  }

 private:
  std::vector<int> parent_;
};

struct CellKey {
  int64_t x, y, z;
  bool operator==(const CellKey& o) const { return x == o.x && y == o.y && z == o.z; }
};

// Canonical vertex per vertex: vertices closer than `tolerance` (transitively) share the
// smallest index of their group. A grid with cell size = tolerance, so only the 27
// neighbouring cells are searched.
std::vector<int> WeldVertices(const std::vector<Eigen::Vector3d>& vertices, double tolerance) {
  const int n = static_cast<int>(vertices.size());
  DisjointSets sets(n);
  // Cell size: the tolerance, or a tiny size for exact welding (then only equal positions,
  // which always share a cell, are within distance 0).
  const double cell = tolerance > 0.0 ? tolerance : 1e-9;
  const double tolerance2 = tolerance > 0.0 ? tolerance * tolerance : 0.0;
  constexpr double kMaxCell = 4e18;
  auto cell_of = [&](double v) {
    return static_cast<int64_t>(std::clamp(std::floor(v / cell), -kMaxCell, kMaxCell));
  };
  // Vertices sorted by cell, and each occupied cell's run in that order (no list per cell:
  // a 10^6-vertex mesh would allocate 10^6 of them).
  std::vector<CellKey> key_of(n);
  std::vector<int> order;
  order.reserve(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d& p = vertices[i];
    if (!p.allFinite()) continue;  // never welded
    key_of[i] = {cell_of(p.x()), cell_of(p.y()), cell_of(p.z())};
    order.push_back(i);
  }
  const auto key_less = [&](int a, int b) {
    const CellKey &ka = key_of[a], &kb = key_of[b];
    return std::tie(ka.x, ka.y, ka.z, a) < std::tie(kb.x, kb.y, kb.z, b);
  };
  std::sort(order.begin(), order.end(), key_less);
  // The occupied cells in key order, each with its run [begin, end) in `order`.
  struct Run {
    CellKey key;
    int begin, end;
  };
  std::vector<Run> runs;
  for (int r = 0; r < static_cast<int>(order.size());) {
    int end = r + 1;
    while (end < static_cast<int>(order.size()) && key_of[order[end]] == key_of[order[r]]) ++end;
    runs.push_back({key_of[order[r]], r, end});
    r = end;
  }
  // Each pair of vertices in the same or neighbouring cells is tested once: within a cell, and
  // against the 13 neighbouring cells that come after it (the union is symmetric).
  const auto test_pairs = [&](int a_begin, int a_end, int b_begin, int b_end, bool same_cell) {
    for (int ra = a_begin; ra < a_end; ++ra) {
      const int i = order[ra];
      const Eigen::Vector3d& p = vertices[i];
      for (int rb = same_cell ? ra + 1 : b_begin; rb < b_end; ++rb) {
        const int j = order[rb];
        if ((vertices[j] - p).squaredNorm() <= tolerance2) sets.Union(i, j);
      }
    }
  };
  std::vector<CellKey> offsets;
  for (int64_t dx = 0; dx <= 1; ++dx)
    for (int64_t dy = dx == 0 ? 0 : -1; dy <= 1; ++dy)
      for (int64_t dz = dx == 0 && dy == 0 ? 1 : -1; dz <= 1; ++dz) offsets.push_back({dx, dy, dz});
  // A cell's neighbour at a given offset comes later in key order as the cell does: one cursor
  // per offset walks the cells once (no lookup per cell; the sets' smallest indices, the
  // result, do not depend on the order the pairs are tested in).
  const auto cell_less = [](const CellKey& a, const CellKey& b) {
    return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
  };
  std::vector<size_t> cursor(offsets.size(), 0);
  for (const Run& run : runs) {
    test_pairs(run.begin, run.end, run.begin, run.end, /*same_cell=*/true);
    for (size_t o = 0; o < offsets.size(); ++o) {
      const CellKey want{run.key.x + offsets[o].x, run.key.y + offsets[o].y,
                         run.key.z + offsets[o].z};
      size_t& c = cursor[o];
      while (c < runs.size() && cell_less(runs[c].key, want)) ++c;
      if (c < runs.size() && runs[c].key == want)
        test_pairs(run.begin, run.end, runs[c].begin, runs[c].end, false);
    }
  }
  std::vector<int> canonical(n);
  for (int i = 0; i < n; ++i) canonical[i] = sets.Find(i);
  return canonical;
}

}  // namespace

MeshAdjacency ComputeAdjacency(const TriangleMesh& mesh, double weld_tolerance_m) {
  MeshAdjacency adjacency;
  adjacency.welded_vertex = WeldVertices(mesh.vertices, weld_tolerance_m);
  const int num_triangles = mesh.NumTriangles();

  // Undirected welded edges with their (triangle, edge k), sorted by edge: the uses of one
  // edge are a run (one array, no list per edge).
  struct EdgeUse {
    uint64_t key;
    int tri;
    int k;
  };
  std::vector<EdgeUse> uses;
  uses.reserve(static_cast<size_t>(num_triangles) * 3);
  const int num_vertices = static_cast<int>(mesh.vertices.size());
  auto welded = [&](int v) { return v >= 0 && v < num_vertices ? adjacency.welded_vertex[v] : -1; };
  for (int t = 0; t < num_triangles; ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = welded(mesh.triangles[t][k]);
      const int b = welded(mesh.triangles[t][(k + 1) % 3]);
      if (a < 0 || b < 0 || a == b) continue;  // invalid or collapsed edge
      const uint64_t key =
          (static_cast<uint64_t>(std::min(a, b)) << 32) | static_cast<uint32_t>(std::max(a, b));
      uses.push_back({key, t, k});
    }
  }
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& a, const EdgeUse& b) {
    return std::tie(a.key, a.tri, a.k) < std::tie(b.key, b.tri, b.k);
  });
  // Each use's slot (3 t + k) gets the other triangles of its run: counted, then filled,
  // then each slot sorted and deduplicated in place and compacted.
  const size_t slots = static_cast<size_t>(num_triangles) * 3;
  std::vector<int64_t> start(slots + 1, 0);
  auto for_each_pair = [&](auto&& fn) {
    for (size_t r = 0; r < uses.size();) {
      size_t end = r + 1;
      while (end < uses.size() && uses[end].key == uses[r].key) ++end;
      for (size_t u = r; end - r >= 2 && u < end; ++u)
        for (size_t o = r; o < end; ++o)
          if (uses[o].tri != uses[u].tri)
            fn(3 * static_cast<size_t>(uses[u].tri) + uses[u].k, uses[o].tri);
      r = end;
    }
  };
  for_each_pair([&](size_t slot, int) { ++start[slot + 1]; });
  for (size_t i = 0; i < slots; ++i) start[i + 1] += start[i];
  std::vector<int> all(static_cast<size_t>(start[slots]));
  std::vector<int64_t> fill(start.begin(), start.end() - 1);
  for_each_pair([&](size_t slot, int other) { all[fill[slot]++] = other; });
  adjacency.offsets.assign(slots + 1, 0);
  int64_t out = 0;
  for (size_t i = 0; i < slots; ++i) {
    int* first = all.data() + start[i];
    int* last = all.data() + start[i + 1];
    std::sort(first, last);
    last = std::unique(first, last);
    for (int* p = first; p < last; ++p) all[out++] = *p;
    adjacency.offsets[i + 1] = out;
  }
  all.resize(static_cast<size_t>(out));
  all.shrink_to_fit();
  adjacency.neighbours = std::move(all);
  return adjacency;
}

}  // namespace fresco
