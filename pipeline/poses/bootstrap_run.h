// The bootstrap step after COLMAP (`fresco poses bootstrap` and the app's Poses panel): places
// the reconstruction in the project's world (from control points, else robustly from the
// given poses; optionally refined by ICP of its sparse points to the mesh) and writes
// OUT/sparse/{cameras,images,points3D}.txt, OUT/project.json (the project pointing at them)
// and OUT/bootstrap.json (alignment, registered frames).
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/poses.h"
#include "pipeline/core/project.h"
#include "pipeline/core/status.h"
#include "pipeline/poses/bootstrap.h"
#include "pipeline/poses/mesh_icp.h"
#include "pipeline/poses/project_colmap.h"

namespace fresco {

struct BootstrapOptions {
  std::vector<ControlPoint> control_points;  // >= 3: align with them, not the given poses
  std::string control_file;                  // where they came from (messages)
  double inlier_position_rel = 0.02;  // given poses within this x scene size support the fit
  double inlier_rotation_deg = 2.0;   // ...and within this
  bool refine_mesh = false;           // then ICP of the sparse points to the mesh
  double refine_max_distance_rel = 0.02;  // ICP pairs within this x scene size
};

struct BootstrapResult {
  Sim3d world_from_colmap;
  ColmapModel model;         // cam_from_world poses (the project's camera as camera 1), points
  std::string aligned_with;  // "control_points" or "given_poses"
  std::vector<double> control_point_residual_m;  // control points
  int inliers = 0, compared = 0;                 // given poses
  bool refined = false;                          // mesh ICP ran
  MeshIcpResult icp;
  double icp_max_distance_m = 0.0;
  std::vector<std::string> not_registered;  // frames COLMAP did not register
};

// Aligns `colmap` (RunColmapOnProject's result) to the scene. Errors name the project's
// poses or scene, or the control-point file.
Status BootstrapFromColmap(const Project& project, const ProjectColmap& colmap,
                           const BootstrapOptions& options, BootstrapResult* result);

// The absolute path of OUT/sparse/images.txt: the bootstrapped project's `poses`.
std::string BootstrapPosesPath(const std::string& out_dir);

// Writes OUT/sparse/*.txt, OUT/project.json (`project` with `poses` = BootstrapPosesPath)
// and OUT/bootstrap.json. OUT/project.json must not be the input project's own file (an
// error says so).
Status WriteBootstrap(const Project& project, const ProjectColmap& colmap,
                      const BootstrapResult& result, const std::string& out_dir);

}  // namespace fresco
