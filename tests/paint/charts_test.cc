// Charts on meshes with noisy normals at every triangle (as photogrammetry and TSDF fusion
// make them): the chart count follows the surface's shape, not its triangle count; charts
// never fold in their plane; their texel stretch stays bounded.
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "pipeline/paint/base_buffer.h"
#include "pipeline/paint/charts.h"
#include "pipeline/paint/grouping.h"
#include "pipeline/synth/procedural_scenes.h"

namespace fresco {
namespace {

// A grid of `cells` x `cells` quads, two triangles each; vertex (i, j), i, j in 0..cells,
// at vertex(i, j) (called row by row); counter-clockwise (front) seen from where i runs
// right and j down.
template <class VertexAt>
TriangleMesh GridMesh(int cells, const VertexAt& vertex) {
  TriangleMesh mesh;
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i) mesh.vertices.push_back(vertex(i, j));
  auto v = [&](int i, int j) { return j * (cells + 1) + i; };
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      mesh.triangles.emplace_back(v(i, j), v(i, j + 1), v(i + 1, j));
      mesh.triangles.emplace_back(v(i + 1, j), v(i, j + 1), v(i + 1, j + 1));
    }
  const int n = mesh.NumTriangles();
  mesh.uvs.assign(n, {Eigen::Vector2f::Zero(), Eigen::Vector2f::Zero(), Eigen::Vector2f::Zero()});
  mesh.material.assign(n, 0);
  mesh.has_uv.assign(n, false);
  return mesh;
}

// A 120-degree arc of a cylinder wall (radius 2 m, 1.5 m high) as a grid of `cells` x
// `cells` quads, each vertex moved along the radius by noise of `noise_m` (1 cm cells and
// 2 mm noise tilt the normals by ~15 degrees at random). It faces the cylinder's axis.
TriangleMesh NoisyCylinderWall(int cells, double noise_m, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_m);
  const double radius = 2.0, height = 1.5, arc = 2.0 * M_PI / 3.0;
  return GridMesh(cells, [&](int i, int j) {
    const double a = arc * (static_cast<double>(i) / cells - 0.5);
    const double r = radius + noise(rng);
    return Eigen::Vector3d(r * std::sin(a), height * j / cells, r * std::cos(a));
  });
}

double AngleSpreadDeg(const TriangleMesh& mesh) {  // RMS angle between neighbours' normals
  double sum = 0;
  int count = 0;
  for (int t = 0; t + 1 < mesh.NumTriangles(); t += 2) {
    const double c = std::clamp(mesh.Normal(t).dot(mesh.Normal(t + 1)), -1.0, 1.0);
    sum += std::pow(std::acos(c) * 180 / M_PI, 2), ++count;
  }
  return std::sqrt(sum / count);
}

TEST(Charts, NoisyNormalsGiveABoundedChartCount) {
  const TriangleMesh mesh = NoisyCylinderWall(150, 0.002, 1);  // 45,000 triangles
  ASSERT_GT(AngleSpreadDeg(mesh), 10.0);                       // the normals really are noisy
  const MeshAdjacency adjacency = ComputeAdjacency(mesh);
  const Grouping paper = ComputeGrouping(mesh, adjacency, 20.0);
  GroupingOptions options;  // defaults: cone 20 deg, charts >= 256 texels, stretch <= 2
  ChartScale scale;
  scale.texel_size_m = 0.005;
  scale.max_chart_texels = 1 << 20;
  const Grouping charts = ComputeCharts(mesh, adjacency, options, scale);
  // 120 degrees of arc in cones of 20 degrees: a handful of charts, whatever the noise.
  EXPECT_LE(charts.groups.size(), 30u);
  EXPECT_GE(charts.groups.size(), 3u);
  EXPECT_GT(paper.groups.size(), 20 * charts.groups.size());
  // Every triangle is in a chart.
  for (int t = 0; t < mesh.NumTriangles(); ++t) ASSERT_GE(charts.group_of_triangle[t], 0) << t;
  const ChartStretch stretch = MeasureChartStretch(mesh, charts);
  EXPECT_LE(stretch.max, 1.05 * options.max_stretch);
  EXPECT_LT(stretch.mean, 1.1);
  // Other noise, other seed: the count stays in the same range.
  const TriangleMesh other = NoisyCylinderWall(200, 0.0015, 2);  // 80,000 triangles
  const Grouping other_charts = ComputeCharts(other, ComputeAdjacency(other), options, scale);
  EXPECT_LE(other_charts.groups.size(), 30u);
}

// A floor of `cells` x `cells` squares of `cell_m` with a block standing on it (the middle
// third raised by 0.2 m), its vertices moved by noise of `noise_m` on each axis: as a TSDF
// mesh whose depth noise reaches the voxel size, normals tilted by ~40 degrees and some
// triangles folded over (facing down). It faces up (+y).
TriangleMesh NoisyFloorWithBlock(int cells, double cell_m, double noise_m, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_m);
  return GridMesh(cells, [&](int i, int j) {
    const bool on_block = i > cells / 3 && i < 2 * cells / 3 && j > cells / 3 && j < 2 * cells / 3;
    const double x = i * cell_m + noise(rng), y = (on_block ? 0.2 : 0.0) + noise(rng);
    return Eigen::Vector3d(x, y, j * cell_m + noise(rng));
  });
}

// Noise at the voxel size (as the 1 cm TSDF meshes of docs/results.md): the charts still
// follow the shape (floor, block top, four sides), the folded triangles share a few charts,
// and no buffer folds.
TEST(Charts, NoiseAtTheVoxelSizeStillGivesAChartPerFace) {
  const TriangleMesh mesh = NoisyFloorWithBlock(200, 0.01, 0.0045, 5);  // 80,000 triangles
  int facing_down = 0;
  for (int t = 0; t < mesh.NumTriangles(); ++t) facing_down += mesh.Normal(t).y() < 0.0;
  ASSERT_GT(facing_down, 200) << facing_down;  // folded over by the noise
  ASSERT_GT(AngleSpreadDeg(mesh), 35.0) << AngleSpreadDeg(mesh);
  GroupingOptions options;
  ChartScale scale;
  scale.texel_size_m = 0.01;
  scale.max_chart_texels = 1 << 20;
  const Grouping charts = ComputeCharts(mesh, ComputeAdjacency(mesh), options, scale);
  // 6 faces, pieces of the sides, and the shared charts of folded triangles (6 directions x
  // a cell or two): 33. Growing over the raw normals made 6,402 charts here, the largest
  // of 618 triangles.
  EXPECT_LE(charts.groups.size(), 40u);
  for (int t = 0; t < mesh.NumTriangles(); ++t) ASSERT_GE(charts.group_of_triangle[t], 0) << t;
  // The largest chart is most of the floor (52,934 of its ~71,000 triangles).
  size_t largest = 0;
  for (const BaseBufferGroup& g : charts.groups) largest = std::max(largest, g.triangles.size());
  EXPECT_GT(largest, 45000u) << charts.groups.size();
  BaseBufferOptions buffer_options;
  buffer_options.texel_size_m = scale.texel_size_m;
  const BaseBufferSet set = BuildBaseBuffers(mesh, charts, buffer_options);
  // Where the shared charts' triangles overlap in their plane, they are split (42 here):
  // 75 buffers (8,506 before).
  EXPECT_LE(set.buffers.size(), 100u) << set.folds_split;
  for (const BaseBuffer& b : set.buffers)
    for (int t : b.triangles) ASSERT_GT(mesh.Normal(t).dot(b.normal), 0.0);  // no fold
  EXPECT_LT(MeasureBufferStretch(mesh, set.buffers).mean, 1.6);
}

TEST(Charts, ChartsNeverFoldInTheirBuffers) {
  const TriangleMesh mesh = NoisyCylinderWall(100, 0.003, 3);
  GroupingOptions options;
  options.angle_deg = 45;  // wide cones: charts that bend a lot
  ChartScale scale;
  scale.texel_size_m = 0.01;
  scale.max_chart_texels = 1 << 20;
  const Grouping charts = ComputeCharts(mesh, ComputeAdjacency(mesh), options, scale);
  BaseBufferOptions buffer_options;
  buffer_options.texel_size_m = scale.texel_size_m;
  const BaseBufferSet set = BuildBaseBuffers(mesh, charts, buffer_options);
  // Against the planes the buffers project onto, every triangle faces its buffer: finite
  // stretch, at most the 1000 that BuildBaseBuffers allows.
  const ChartStretch stretch = MeasureBufferStretch(mesh, set.buffers);
  EXPECT_GE(stretch.max, 1.0);
  EXPECT_LE(stretch.max, 1000.0);
  EXPECT_LT(stretch.mean, 1.5);
  for (const BaseBuffer& b : set.buffers) {
    // Folding would put two triangles over one texel: the triangles' projected areas would
    // add up to more than the texels they cover.
    double projected_texels = 0;
    for (int t : b.triangles) {
      const Eigen::Vector2d q0 = b.TexelCoords(mesh.Corner(t, 0));
      const Eigen::Vector2d q1 = b.TexelCoords(mesh.Corner(t, 1));
      const Eigen::Vector2d q2 = b.TexelCoords(mesh.Corner(t, 2));
      const Eigen::Vector2d e1 = q1 - q0, e2 = q2 - q0;
      projected_texels += 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
      EXPECT_GT(mesh.Normal(t).dot(b.normal), 0.0);  // front side up in its plane
    }
    if (projected_texels < 200) continue;  // too small to compare areas with texel counts
    EXPECT_NEAR(b.num_surface_texels / projected_texels, 1.0, 0.05)
        << "buffer of " << b.triangles.size() << " triangles";
  }
}

TEST(Charts, PlanarModelsKeepOneChartPerFace) {
  CubeRoomOptions room;
  room.procedural_texture_px = 64;
  Scene scene;
  ASSERT_TRUE(MakeCubeRoomScene(room, &scene).ok());
  GroupingOptions options;
  ChartScale scale;
  scale.texel_size_m = 0.01;
  scale.max_chart_texels = 1 << 22;
  EXPECT_EQ(ComputeCharts(scene.mesh, ComputeAdjacency(scene.mesh), options, scale).groups.size(),
            6u);
  // A chart does not grow beyond 4x the largest buffer: it is split instead of getting much
  // coarser texels.
  scale.max_chart_texels = 20000;  // 4 x 2 m^2 at 1 cm: one triangle (6-8 m^2) per chart
  const Grouping limited = ComputeCharts(scene.mesh, ComputeAdjacency(scene.mesh), options, scale);
  EXPECT_GT(limited.groups.size(), 6u);
}

// A chunk is culled as facing away only when every one of its texels faces away, judged
// with the stored (quantized) points and normals the warp uses; and from behind the wall
// most chunks are culled. Cameras all around a noisy wall (normals tilted ~15 degrees).
TEST(Charts, ChunksCulledAsFacingAwayHoldOnlyTexelsFacingAway) {
  const TriangleMesh mesh = NoisyCylinderWall(100, 0.003, 4);
  GroupingOptions options;
  ChartScale scale;
  scale.texel_size_m = 0.01;
  scale.max_chart_texels = 1 << 20;
  const Grouping charts = ComputeCharts(mesh, ComputeAdjacency(mesh), options, scale);
  BaseBufferOptions buffer_options;
  buffer_options.texel_size_m = scale.texel_size_m;
  const BaseBufferSet set = BuildBaseBuffers(mesh, charts, buffer_options);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> angle(-M_PI, M_PI), radius(0.2f, 6.0f), y(-1.0f, 2.5f);
  long long culled = 0, all_away = 0;  // chunks culled; chunks whose texels all face away
  for (int trial = 0; trial < 200; ++trial) {
    const float a = angle(rng), r = radius(rng);
    const Eigen::Vector3f centre(r * std::sin(a), y(rng), r * std::cos(a));
    for (const BaseBuffer& b : set.buffers)
      for (const BaseBuffer::Chunk& chunk : b.chunks) {
        bool away = true;
        for (int k = chunk.begin; k < chunk.end && away; ++k)
          away = b.Normal(k).dot(centre - b.PointIn(chunk, k)) < 0.0f;
        all_away += away;
        if (!chunk.FacesAwayFrom(centre)) continue;
        ++culled;
        ASSERT_TRUE(away) << "trial " << trial << " chunk " << chunk.begin;
      }
  }
  // Conservative: 47 % of the chunks that could be culled are here, where the noise widens
  // the chunks' normal cones (on planar surfaces the cones are thin and nearly all are).
  EXPECT_GT(culled, all_away * 4 / 10) << all_away;
}

}  // namespace
}  // namespace fresco
