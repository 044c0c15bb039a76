#include "pipeline/synth/mesh_refine.h"

#include <cmath>
#include <cstdint>
#include <string>

namespace fresco {
namespace {

uint64_t Mix(uint64_t x) {  // splitmix64's finaliser
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// Three independent standard normal values from a position (on a 10 um grid) and the seed.
Eigen::Vector3d NoiseAt(const Eigen::Vector3d& p, unsigned seed) {
  uint64_t h = Mix(seed);
  for (int k = 0; k < 3; ++k) h = Mix(h ^ static_cast<uint64_t>(std::llround(p[k] * 1e5)));
  Eigen::Vector3d n;
  for (int k = 0; k < 3; ++k) {
    const uint64_t a = Mix(h + 2 * k), b = Mix(h + 2 * k + 1);
    const double u1 = (static_cast<double>(a >> 11) + 0.5) / 9007199254740992.0;
    const double u2 = static_cast<double>(b >> 11) / 9007199254740992.0;
    n[k] = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);  // Box-Muller
  }
  return n;
}

}  // namespace

Status RefineMesh(const MeshRefineOptions& options, Scene* scene) {
  const int n = options.subdivide;
  if (n < 1) return Status::Error("mesh.subdivide: must be at least 1, got " + std::to_string(n));
  if (!(options.noise_m >= 0))
    return Status::Error("mesh.noise_m: must be >= 0, got " + std::to_string(options.noise_m));
  const TriangleMesh& in = scene->mesh;
  const double triangles = static_cast<double>(in.NumTriangles()) * n * n;
  if (triangles > (1 << 28))
    return Status::Error("mesh.subdivide: " + std::to_string(n) + " would make " +
                         std::to_string(static_cast<long long>(triangles)) +
                         " triangles (at most 2^28)");
  TriangleMesh out;
  out.vertices.reserve(static_cast<size_t>(in.NumTriangles()) * (n + 1) * (n + 2) / 2);
  out.triangles.reserve(static_cast<size_t>(triangles));
  for (int t = 0; t < in.NumTriangles(); ++t) {
    const Eigen::Vector3d a = in.Corner(t, 0), b = in.Corner(t, 1), c = in.Corner(t, 2);
    const auto& uv = in.uvs[t];
    const int first = static_cast<int>(out.vertices.size());
    // Vertex (i, j) = a + i/n (b - a) + j/n (c - a), i + j <= n, row by row in j.
    std::vector<int> row_start(n + 2);
    for (int j = 0; j <= n; ++j) {
      row_start[j] = static_cast<int>(out.vertices.size()) - first;
      for (int i = 0; i + j <= n; ++i) {
        const double u = static_cast<double>(i) / n, v = static_cast<double>(j) / n;
        Eigen::Vector3d p = a + u * (b - a) + v * (c - a);
        if (options.noise_m > 0) {
          const Eigen::Vector3d world = scene->WorldFromLocal(p);
          p += options.noise_m * NoiseAt(world, options.seed);
        }
        out.vertices.push_back(p);
      }
    }
    auto vertex = [&](int i, int j) { return first + row_start[j] + i; };
    auto uv_at = [&](int i, int j) {
      const float u = static_cast<float>(i) / n, v = static_cast<float>(j) / n;
      return Eigen::Vector2f(uv[0] + u * (uv[1] - uv[0]) + v * (uv[2] - uv[0]));
    };
    auto add = [&](int i0, int j0, int i1, int j1, int i2, int j2) {
      out.triangles.emplace_back(vertex(i0, j0), vertex(i1, j1), vertex(i2, j2));
      out.uvs.push_back({uv_at(i0, j0), uv_at(i1, j1), uv_at(i2, j2)});
      out.material.push_back(in.material[t]);
      out.has_uv.push_back(in.has_uv[t]);
    };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i + j < n; ++i) {
        add(i, j, i + 1, j, i, j + 1);  // same winding as (a, b, c)
        if (i + j + 1 < n) add(i + 1, j, i + 1, j + 1, i, j + 1);
      }
  }
  scene->mesh = std::move(out);
  return Status::Ok();
}

}  // namespace fresco
