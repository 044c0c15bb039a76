// Large noisy meshes for painting tests (fresco synth "mesh"): subdivision keeps the surface
// and its UVs, noise keeps a closed mesh closed.
#include <gtest/gtest.h>

#include "pipeline/synth/mesh_refine.h"
#include "pipeline/synth/procedural_scenes.h"

namespace fresco {
namespace {

double TotalArea(const TriangleMesh& mesh) {
  double a = 0;
  for (int t = 0; t < mesh.NumTriangles(); ++t) a += mesh.Area(t);
  return a;
}

TEST(MeshRefine, SubdivisionKeepsTheSurfaceAndItsUvs) {
  Scene scene = MakeTexturedCubeScene(1.0);
  const Scene before = scene;
  MeshRefineOptions options;
  options.subdivide = 5;
  ASSERT_TRUE(RefineMesh(options, &scene).ok());
  ASSERT_EQ(scene.mesh.NumTriangles(), 25 * before.mesh.NumTriangles());
  EXPECT_NEAR(TotalArea(scene.mesh), TotalArea(before.mesh), 1e-9);
  // Every small triangle lies in its original triangle's plane, with the same winding, and
  // its UVs are the original's at its corners (the first one sits at corner 0).
  for (int t = 0; t < before.mesh.NumTriangles(); ++t) {
    const int first = 25 * t;
    EXPECT_GT(scene.mesh.Normal(first).dot(before.mesh.Normal(t)), 1 - 1e-12);
    EXPECT_LT((scene.mesh.Corner(first, 0) - before.mesh.Corner(t, 0)).norm(), 1e-12);
    EXPECT_LT((scene.mesh.uvs[first][0] - before.mesh.uvs[t][0]).norm(), 1e-6);
    EXPECT_EQ(scene.mesh.material[first], before.mesh.material[t]);
  }
}

TEST(MeshRefine, NoiseMovesSharedVerticesTogether) {
  Scene scene = MakeTexturedCubeScene(1.0);
  MeshRefineOptions options;
  options.subdivide = 8;
  options.noise_m = 0.01;
  ASSERT_TRUE(RefineMesh(options, &scene).ok());
  // Normals are noisy...
  Scene smooth = MakeTexturedCubeScene(1.0);
  options.noise_m = 0;
  ASSERT_TRUE(RefineMesh(options, &smooth).ok());
  double moved = 0;
  for (size_t v = 0; v < scene.mesh.vertices.size(); ++v)
    moved += (scene.mesh.vertices[v] - smooth.mesh.vertices[v]).norm();
  EXPECT_GT(moved / scene.mesh.vertices.size(), 0.01);
  // ...and the cube is still closed: every edge has exactly one neighbour across it.
  const MeshAdjacency adjacency = ComputeAdjacency(scene.mesh);
  for (int t = 0; t < scene.mesh.NumTriangles(); ++t)
    for (int k = 0; k < 3; ++k) ASSERT_EQ(adjacency.EdgeNeighbours(t, k).size(), 1u) << t;
}

TEST(MeshRefine, RefusesBadSettings) {
  Scene scene = MakeTexturedCubeScene(1.0);
  MeshRefineOptions options;
  options.subdivide = 0;
  EXPECT_FALSE(RefineMesh(options, &scene).ok());
  options.subdivide = 100000;
  EXPECT_NE(RefineMesh(options, &scene).message().find("at most 2^28"), std::string::npos);
  options.subdivide = 2;
  options.noise_m = -1;
  EXPECT_FALSE(RefineMesh(options, &scene).ok());
}

}  // namespace
}  // namespace fresco
