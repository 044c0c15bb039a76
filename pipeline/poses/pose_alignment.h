// Aligning a COLMAP reconstruction (arbitrary scale, rotation, translation) to the project's
// given poses: a robust similarity world_from_colmap from the camera centres (RANSAC over
// minimal sets, similarity.h), whose rotation is then refined from the camera orientations
// (chordal mean of the per-frame world_from_colmap rotations of the inliers, orientation
// outliers rejected) and its scale and translation refitted with that rotation, then once
// more with thresholds from the inliers' own spread. Outlier poses (by position or
// orientation) do not bend the fit. Also the per-frame disagreement of a
// given pose with an aligned COLMAP pose.
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"
#include "pipeline/poses/similarity.h"

namespace fresco {

// One frame with both a given pose and a COLMAP pose.
struct PosePair {
  std::string name;
  Rigid3d given_cam_from_world;
  Rigid3d colmap_cam_from_colmap;
};

struct PoseAlignmentOptions {
  // A frame supports the fit when its aligned camera centre is within this of the given one
  // (metres) and its orientation within `inlier_rotation_deg`.
  double inlier_position_m = 0.05;
  double inlier_rotation_deg = 0.5;
  int iterations = 500;  // RANSAC trials
  unsigned seed = 1;
  // After the fit (with >= 6 inliers), the thresholds shrink to this many times the
  // inliers' median errors (but not below 5 % of the thresholds above) and the fit is
  // redone: poses a little off stop bending it. 0 = off.
  double adaptive_factor = 3.0;

  Status Check() const;
};

struct PoseAlignment {
  Sim3d world_from_colmap;
  std::vector<bool> inliers;  // per pair
  int num_inliers = 0;
};

// Needs >= 3 pairs whose camera centres are not collinear.
Status AlignColmapToPoses(const std::vector<PosePair>& pairs, const PoseAlignmentOptions& options,
                          PoseAlignment* alignment);

// Disagreement of the given pose with the COLMAP pose brought into the world.
struct PoseError {
  double rotation_deg = 0.0;
  double position_m = 0.0;  // distance between camera centres
};
PoseError ComparePose(const PosePair& pair, const Sim3d& world_from_colmap);

}  // namespace fresco
