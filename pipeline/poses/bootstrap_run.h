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
  double inlier_position_rel = 0.02;         // given poses within this x scene size support the fit
  double inlier_rotation_deg = 2.0;          // ...and within this
  bool refine_mesh = false;                  // then ICP of the sparse points to the mesh
  double refine_max_distance_rel = 0.02;     // ICP pairs within this x scene size
  // A given pose agrees with its bootstrapped one within these (the verification's
  // thresholds: stricter than the fit's, so a reconstruction that bends is not vouched for).
  double agree_rotation_deg = 0.5;
  double agree_position_rel = 0.01;  // x scene size
};

// The bootstrapped poses against the given ones on the frames both have: are they better?
// Aligned with the given poses, they are better when most given poses agree with them
// within the verification's thresholds (the others are replaced by poses the majority
// vouches for), and likely worse when fewer than half do (a reconstruction that bends or
// breaks: the alignment's looser thresholds may still take it). Aligned with control points, a
// majority agreeing says both are right; otherwise the two disagree and nothing here says which is
// right.
struct PosesComparison {
  int compared = 0;  // frames with both a given and a bootstrapped pose
  int agreeing = 0;  // within BootstrapOptions::agree_*
  double median_rotation_deg = 0.0, max_rotation_deg = 0.0;  // bootstrapped vs given
  double median_position_m = 0.0, max_position_m = 0.0;
  bool collinear = false;  // the given centres lie on a line (the rotation from orientations)
  // The two differ smoothly along the sequence (a drift of one of them: which is better is
  // then "unknown").
  bool drifts = false;
  // Where it drifts: the first and last frame of the stretch where the drift itself carries
  // frames beyond the thresholds, as `fresco poses verify` names it (VerifyResult::drift_first,
  // drift_last; else the first and last frame that differs smoothly).
  std::string drift_first, drift_last;
  // "bootstrapped", "given" (the bootstrapped are likely worse), "unknown" (one of the two
  // drifts, or control points disagree with the given poses), "none" (no frame to compare).
  std::string better;
  std::string summary;  // one sentence for the CLI and the panel
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
  PosesComparison comparison;
};

// Aligns `colmap` (RunColmapOnProject's result) to the scene. Errors name the project's
// poses or scene, or the control-point file; they are failed work (StatusKind::kFailed):
// the inputs were read before.
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
