// TriangleMesh geometry (normal, area), Scene::Bounds and ComputeAdjacency (welding + edges).
#include <numeric>
#include <random>
#include <set>
#include <span>
#include <vector>

#include <gtest/gtest.h>

#include "pipeline/core/scene.h"

namespace fresco {
namespace {

// One edge's neighbours as a vector (to compare with expected lists).
std::vector<int> Vec(std::span<const int> s) { return std::vector<int>(s.begin(), s.end()); }

// A unit cube centred at `centre` with 4 vertices per face (split at every UV seam, as glTF
// exporters do): 24 vertices, 12 counter-clockwise (outward) triangles.
TriangleMesh SplitCube(const Eigen::Vector3d& centre = Eigen::Vector3d::Zero()) {
  TriangleMesh mesh;
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                        z = Eigen::Vector3d::UnitZ();
  // (normal, u, v) with u x v = normal.
  const std::array<std::array<Eigen::Vector3d, 3>, 6> faces = {
      {{x, y, z}, {-x, z, y}, {y, z, x}, {-y, x, z}, {z, x, y}, {-z, y, x}}};
  for (const auto& [n, u, v] : faces) {
    const int base = static_cast<int>(mesh.vertices.size());
    mesh.vertices.push_back(centre + 0.5 * (n - u - v));
    mesh.vertices.push_back(centre + 0.5 * (n + u - v));
    mesh.vertices.push_back(centre + 0.5 * (n + u + v));
    mesh.vertices.push_back(centre + 0.5 * (n - u + v));
    mesh.triangles.emplace_back(base, base + 1, base + 2);
    mesh.triangles.emplace_back(base, base + 2, base + 3);
  }
  const int t = mesh.NumTriangles();
  mesh.uvs.assign(t, {Eigen::Vector2f::Zero(), Eigen::Vector2f::Zero(), Eigen::Vector2f::Zero()});
  mesh.material.assign(t, 0);
  mesh.has_uv.assign(t, false);
  return mesh;
}

TEST(TriangleMeshTest, NormalAndArea) {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {2, 0, 0}, {0, 3, 0}, {1, 0, 0}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 1}, {0, 1, 3}};
  EXPECT_NEAR(mesh.Area(0), 3.0, 1e-15);
  EXPECT_TRUE(mesh.Normal(0).isApprox(Eigen::Vector3d(0, 0, 1)));
  EXPECT_TRUE(mesh.Normal(1).isApprox(Eigen::Vector3d(0, 0, -1)));  // clockwise
  // Collinear: zero area, zero normal.
  EXPECT_EQ(mesh.Area(2), 0.0);
  EXPECT_EQ(mesh.Normal(2), Eigen::Vector3d::Zero());
}

TEST(TriangleMeshTest, CubeNormalsPointOutward) {
  const TriangleMesh mesh = SplitCube();
  for (int t = 0; t < mesh.NumTriangles(); ++t) {
    const Eigen::Vector3d centroid =
        (mesh.Corner(t, 0) + mesh.Corner(t, 1) + mesh.Corner(t, 2)) / 3;
    EXPECT_GT(mesh.Normal(t).dot(centroid), 0.49) << "triangle " << t;
    EXPECT_NEAR(mesh.Area(t), 0.5, 1e-15);
  }
}

TEST(SceneTest, BoundsOfVertices) {
  Scene scene;
  scene.mesh = SplitCube(Eigen::Vector3d(1, 2, 3));
  Eigen::Vector3d lo, hi;
  scene.Bounds(&lo, &hi);
  EXPECT_EQ(lo, Eigen::Vector3d(0.5, 1.5, 2.5));
  EXPECT_EQ(hi, Eigen::Vector3d(1.5, 2.5, 3.5));
  Scene empty;
  empty.Bounds(&lo, &hi);
  EXPECT_EQ(lo, Eigen::Vector3d::Zero());
  EXPECT_EQ(hi, Eigen::Vector3d::Zero());
}

TEST(AdjacencyTest, SplitCubeWeldsToClosedManifold) {
  const TriangleMesh mesh = SplitCube(Eigen::Vector3d(1e3, -2e3, 5));
  const MeshAdjacency adjacency = ComputeAdjacency(mesh);
  ASSERT_EQ(adjacency.welded_vertex.size(), 24u);
  const std::set<int> corners(adjacency.welded_vertex.begin(), adjacency.welded_vertex.end());
  EXPECT_EQ(corners.size(), 8u);  // 24 split vertices -> 8 cube corners
  for (int v = 0; v < 24; ++v) {
    const int w = adjacency.welded_vertex[v];
    EXPECT_LE(w, v);
    EXPECT_EQ(mesh.vertices[w], mesh.vertices[v]);
  }
  ASSERT_EQ(adjacency.NumTriangles(), 12);
  for (int t = 0; t < 12; ++t) {
    std::set<int> neighbours;
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(adjacency.EdgeNeighbours(t, k).size(), 1u) << "triangle " << t << " edge " << k;
      const int other = adjacency.EdgeNeighbours(t, k)[0];
      neighbours.insert(other);
      // The neighbour really shares this edge's (welded) end points.
      const Eigen::Vector3d a = mesh.Corner(t, k), b = mesh.Corner(t, (k + 1) % 3);
      int shared = 0;
      for (int j = 0; j < 3; ++j) {
        shared += mesh.Corner(other, j) == a || mesh.Corner(other, j) == b;
      }
      EXPECT_EQ(shared, 2);
    }
    EXPECT_EQ(neighbours.size(), 3u) << "triangle " << t;
    EXPECT_EQ(neighbours.count(t), 0u);
  }
}

TEST(AdjacencyTest, WithoutWeldingSplitSeamsAreOpen) {
  // Tolerance 0 still welds exactly coincident vertices.
  const MeshAdjacency exact = ComputeAdjacency(SplitCube(), 0.0);
  for (int t = 0; t < 12; ++t) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(exact.EdgeNeighbours(t, k).size(), 1u);
  }
  // Move one face's vertices slightly apart: that face separates from the rest.
  TriangleMesh mesh = SplitCube();
  for (int v = 0; v < 4; ++v) mesh.vertices[v] += Eigen::Vector3d(0.5e-6, 0, 0);
  const MeshAdjacency loose = ComputeAdjacency(mesh, 1e-6);
  const MeshAdjacency tight = ComputeAdjacency(mesh, 1e-7);
  int loose_links = 0, tight_links = 0;
  for (int t = 0; t < 12; ++t) {
    for (int k = 0; k < 3; ++k) {
      loose_links += static_cast<int>(loose.EdgeNeighbours(t, k).size());
      tight_links += static_cast<int>(tight.EdgeNeighbours(t, k).size());
    }
  }
  EXPECT_EQ(loose_links, 36);
  // The moved face's 4 outer edges and the 4 edges of its neighbours lose their partner.
  EXPECT_EQ(tight_links, 36 - 8);
}

TEST(AdjacencyTest, WeldsAcrossGridCellBoundaries) {
  // Two triangles whose shared edge vertices straddle a hash-grid cell boundary (cell size =
  // tolerance, boundary at x = 1e-6).
  TriangleMesh mesh;
  mesh.vertices = {{0.99e-6, 0, 0}, {0.99e-6, 1, 0}, {-1, 0, 0},
                   {1.01e-6, 0, 0}, {1.01e-6, 1, 0}, {1, 0, 0}};
  mesh.triangles = {{0, 1, 2}, {3, 5, 4}};
  const MeshAdjacency adjacency = ComputeAdjacency(mesh, 1e-6);
  EXPECT_EQ(adjacency.welded_vertex[3], 0);
  EXPECT_EQ(adjacency.welded_vertex[4], 1);
  EXPECT_EQ(Vec(adjacency.EdgeNeighbours(0, 0)), std::vector<int>{1});
  EXPECT_EQ(Vec(adjacency.EdgeNeighbours(1, 2)), std::vector<int>{0});
  EXPECT_TRUE(adjacency.EdgeNeighbours(0, 1).empty());
}

// Welding against every pair tested by brute force: random points in a box a few cells
// across, close pairs in every direction (the neighbouring cells before and after a cell on
// each axis); each vertex's welded index is the smallest of those it is chained to.
TEST(AdjacencyTest, WeldingMatchesEveryPairTested) {
  const double tolerance = 0.1;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> in_box(-0.35, 0.35);
  TriangleMesh mesh;
  for (int i = 0; i < 600; ++i)
    mesh.vertices.emplace_back(in_box(random), in_box(random), in_box(random));
  for (int i = 0; i + 2 < 600; i += 3) mesh.triangles.emplace_back(i, i + 1, i + 2);
  const int n = static_cast<int>(mesh.vertices.size());
  std::vector<int> smallest(n);
  std::iota(smallest.begin(), smallest.end(), 0);
  for (bool changed = true; changed;) {  // until every chain carries its smallest index
    changed = false;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        if ((mesh.vertices[i] - mesh.vertices[j]).norm() <= tolerance &&
            smallest[j] < smallest[i]) {
          smallest[i] = smallest[j];
          changed = true;
        }
  }
  const MeshAdjacency adjacency = ComputeAdjacency(mesh, tolerance);
  EXPECT_EQ(adjacency.welded_vertex, smallest);
  EXPECT_LT(std::set<int>(smallest.begin(), smallest.end()).size(), 600u);  // some welded
  EXPECT_GT(std::set<int>(smallest.begin(), smallest.end()).size(), 1u);    // not all
}

TEST(AdjacencyTest, NonManifoldFanEdgeListsAllOthers) {
  // Four triangles hinged on the edge (0, 1) like pages of a book.
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}};
  mesh.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}, {1, 0, 5}};
  const MeshAdjacency adjacency = ComputeAdjacency(mesh);
  EXPECT_EQ(Vec(adjacency.EdgeNeighbours(0, 0)), (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(Vec(adjacency.EdgeNeighbours(1, 0)), (std::vector<int>{0, 2, 3}));
  EXPECT_EQ(Vec(adjacency.EdgeNeighbours(2, 0)), (std::vector<int>{0, 1, 3}));
  EXPECT_EQ(Vec(adjacency.EdgeNeighbours(3, 0)), (std::vector<int>{0, 1, 2}));
  for (int t = 0; t < 4; ++t) {
    EXPECT_TRUE(adjacency.EdgeNeighbours(t, 1).empty());
    EXPECT_TRUE(adjacency.EdgeNeighbours(t, 2).empty());
  }
}

TEST(AdjacencyTest, LargeGridInteriorHasThreeNeighbours) {
  // 300 x 300 quads, vertices duplicated per quad (4 per quad, 360k vertices): only a hash
  // grid welds this quickly.
  const int n = 300;
  TriangleMesh mesh;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const int base = static_cast<int>(mesh.vertices.size());
      mesh.vertices.push_back({0.01 * i, 0.01 * j, 0});
      mesh.vertices.push_back({0.01 * (i + 1), 0.01 * j, 0});
      mesh.vertices.push_back({0.01 * (i + 1), 0.01 * (j + 1), 0});
      mesh.vertices.push_back({0.01 * i, 0.01 * (j + 1), 0});
      mesh.triangles.emplace_back(base, base + 1, base + 2);
      mesh.triangles.emplace_back(base, base + 2, base + 3);
    }
  }
  const MeshAdjacency adjacency = ComputeAdjacency(mesh, 1e-6);
  const std::set<int> welded(adjacency.welded_vertex.begin(), adjacency.welded_vertex.end());
  EXPECT_EQ(welded.size(), static_cast<size_t>((n + 1) * (n + 1)));
  int boundary_edges = 0;
  for (int t = 0; t < mesh.NumTriangles(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const size_t count = adjacency.EdgeNeighbours(t, k).size();
      ASSERT_LE(count, 1u);
      boundary_edges += count == 0;
    }
  }
  EXPECT_EQ(boundary_edges, 4 * n);
}

}  // namespace
}  // namespace fresco
