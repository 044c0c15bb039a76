// Groups whose triangles lie scattered over their plane are built as compact buffers: a
// buffer's arrays cover its whole rectangle, so pieces far apart in one buffer cost texels
// no triangle owns (and, past the buffer size cap, coarser texels for the pieces).
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "pipeline/paint/base_buffer.h"
#include "pipeline/paint/scattered_groups.h"

namespace fresco {
namespace {

// `count` squares of side `side_m` on the plane z = 2 (facing -z), their corners at random
// within a `spread_m` square; two triangles each.
TriangleMesh ScatteredSquares(int count, double side_m, double spread_m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> at(0.0, spread_m - side_m);
  TriangleMesh mesh;
  for (int k = 0; k < count; ++k) {
    const double x = at(rng), y = at(rng);
    const int v = static_cast<int>(mesh.vertices.size());
    mesh.vertices.emplace_back(x, y, 2.0);
    mesh.vertices.emplace_back(x + side_m, y, 2.0);
    mesh.vertices.emplace_back(x, y + side_m, 2.0);
    mesh.vertices.emplace_back(x + side_m, y + side_m, 2.0);
    mesh.triangles.emplace_back(v, v + 1, v + 2);
    mesh.triangles.emplace_back(v + 1, v + 3, v + 2);
  }
  const int n = mesh.NumTriangles();
  mesh.uvs.assign(n, {Eigen::Vector2f::Zero(), Eigen::Vector2f::Zero(), Eigen::Vector2f::Zero()});
  mesh.material.assign(n, 0);
  mesh.has_uv.assign(n, false);
  return mesh;
}

Grouping OneGroup(const TriangleMesh& mesh) {
  Grouping grouping;
  grouping.groups.emplace_back();
  for (int t = 0; t < mesh.NumTriangles(); ++t) grouping.groups[0].triangles.push_back(t);
  grouping.RebuildIndex(mesh.NumTriangles());
  return grouping;
}

TEST(ScatteredGroups, PiecesFarApartOnOnePlaneGetCompactBuffersAtTheirTexelSize) {
  // 16 squares of 2 cm over 2 m, at 2 mm texels: 1,600 surface texels; as one buffer a
  // 1000 x 1000-texel rectangle, over the 2^20 cap (so coarser texels).
  const TriangleMesh mesh = ScatteredSquares(16, 0.02, 2.0, 7);
  BaseBufferOptions options;
  options.texel_size_m = 0.002;
  const BaseBufferSet set = BuildBaseBuffers(mesh, OneGroup(mesh), options);
  long long surface = 0, rectangles = 0;
  std::multiset<int> triangles;
  for (const BaseBuffer& b : set.buffers) {
    EXPECT_DOUBLE_EQ(b.texel_size_m, 0.002);
    surface += b.num_surface_texels;
    rectangles += static_cast<long long>(b.width) * b.height;
    triangles.insert(b.triangles.begin(), b.triangles.end());
  }
  EXPECT_GT(set.buffers.size(), 1u);
  EXPECT_EQ(set.scattered_split, 1);
  EXPECT_NEAR(surface, 1600, 80);
  // Each square alone: (10 + 2 x gutter + 1)^2 = 225 texels; a rectangle may hold a few.
  EXPECT_LE(rectangles, 16 * 225 * 3);
  // Every triangle in exactly one buffer.
  ASSERT_EQ(triangles.size(), static_cast<size_t>(mesh.NumTriangles()));
  for (int t = 0; t < mesh.NumTriangles(); ++t) EXPECT_EQ(triangles.count(t), 1u) << t;
}

TEST(ScatteredGroups, ACompactGroupStaysWhole) {
  // 400 squares of 2 cm tiling a 40 cm square: no cut saves anything.
  TriangleMesh mesh;
  for (int j = 0; j < 20; ++j)
    for (int i = 0; i < 20; ++i) {
      const TriangleMesh one = ScatteredSquares(1, 0.02, 0.02, 1);  // a square at (0, 0)
      const int v = static_cast<int>(mesh.vertices.size());
      for (const Eigen::Vector3d& p : one.vertices)
        mesh.vertices.push_back(p + Eigen::Vector3d(0.02 * i, 0.02 * j, 0));
      for (const Eigen::Vector3i& t : one.triangles) mesh.triangles.push_back(t.array() + v);
    }
  const Grouping grouping = OneGroup(mesh);
  EXPECT_EQ(SplitScatteredGroup(mesh, grouping.groups[0], 0.002, 2).size(), 1u);
  // A few squares far apart are cut, each piece in order.
  const TriangleMesh scattered = ScatteredSquares(6, 0.02, 3.0, 3);
  const std::vector<BaseBufferGroup> pieces =
      SplitScatteredGroup(scattered, OneGroup(scattered).groups[0], 0.002, 2);
  EXPECT_GE(pieces.size(), 3u);
  for (const BaseBufferGroup& piece : pieces)
    EXPECT_TRUE(std::is_sorted(piece.triangles.begin(), piece.triangles.end()));
}

}  // namespace
}  // namespace fresco
