// libFuzzer target: glTF / GLB bytes through our adapter (ParseGltfScene: tinygltf from
// memory, then our validation and flattening). External URIs point into a folder that does
// not exist, so an input is all there is. An accepted scene must be self-consistent.
#include "pipeline/core/scene.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fresco::Scene scene;
  if (!fresco::ParseGltfScene(fresco::fuzz::AsText(data, size), "/fuzz/scene.gltf",
                              "/nonexistent-fresco-fuzz", fresco::SceneLoadOptions(), &scene)
           .ok()) {
    return 0;
  }
  const fresco::TriangleMesh& mesh = scene.mesh;
  const int num_vertices = static_cast<int>(mesh.vertices.size());
  FUZZ_CHECK(mesh.material.size() == mesh.triangles.size());
  FUZZ_CHECK(mesh.uvs.size() == mesh.triangles.size());
  FUZZ_CHECK(mesh.has_uv.size() == mesh.triangles.size());
  FUZZ_CHECK(!scene.materials.empty());
  for (int t = 0; t < mesh.NumTriangles(); ++t) {
    for (int k = 0; k < 3; ++k) {
      FUZZ_CHECK(mesh.triangles[t][k] >= 0 && mesh.triangles[t][k] < num_vertices);
      FUZZ_CHECK(mesh.uvs[t][k].allFinite());
    }
    FUZZ_CHECK(mesh.material[t] >= 0 && mesh.material[t] < static_cast<int>(scene.materials.size()));
  }
  for (const Eigen::Vector3d& v : mesh.vertices) FUZZ_CHECK(v.allFinite());
  for (const fresco::Material& material : scene.materials) {
    FUZZ_CHECK(material.base_color_texture < static_cast<int>(scene.textures.size()));
  }
  const fresco::MeshAdjacency adjacency = fresco::ComputeAdjacency(mesh);
  FUZZ_CHECK(adjacency.NumTriangles() == static_cast<int>(mesh.triangles.size()));
  return 0;
}
