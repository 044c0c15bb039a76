// Optional refinement of a COLMAP reconstruction's placement against the scene's mesh:
// ICP of COLMAP's sparse points to the model, point-to-plane, over a similarity (scale,
// rotation, translation), starting from an alignment that is nearly right (from control
// points or given poses). The mesh is sampled densely (area-weighted points with their
// triangle's normal) and searched with a voxel hash; each iteration pairs every point with
// its nearest sample within `max_distance`, rejects pairs beyond 3x the median distance
// (points off the model: background, noise), and solves the linearised 7-parameter
// point-to-plane least squares with Huber weights. Pure computation, no files.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "pipeline/core/scene.h"
#include "pipeline/core/status.h"
#include "pipeline/poses/similarity.h"

namespace fresco {

struct MeshIcpOptions {
  // Pairs farther apart than this (metres, world) are ignored. Must be > 0.
  double max_distance_m = 0.1;
  // Mesh sample spacing (metres); 0 = max_distance_m / 8.
  double sample_spacing_m = 0.0;
  int max_samples = 2000000;  // spacing grows when the mesh would need more samples
  int iterations = 30;        // at most; stops when the update is below 1e-6 (relative)
  bool estimate_scale = true;
  int min_pairs = 20;  // fewer pairs is an error (nothing to align with)

  Status Check() const;
};

struct MeshIcpResult {
  Sim3d world_from_colmap;
  int pairs = 0;       // point-to-mesh pairs used in the last iteration
  int iterations = 0;  // iterations run
  // Median point-to-plane distance of the points within max_distance of the mesh, before
  // and after.
  double median_distance_before_m = 0.0;
  double median_distance_after_m = 0.0;
};

// `points_in_colmap`: (N) COLMAP's sparse points; `initial`: world_from_colmap to start
// from; the scene's mesh in world coordinates.
Status AlignPointsToMesh(const std::vector<Eigen::Vector3d>& points_in_colmap, const Scene& scene,
                         const Sim3d& initial, const MeshIcpOptions& options,
                         MeshIcpResult* result);

}  // namespace fresco
